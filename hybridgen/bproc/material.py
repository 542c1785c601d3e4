"""``bproc.material``: the scene's materials (BlenderProc's MaterialLoaderUtility); node-building helpers raise
one line naming the call."""
from __future__ import annotations

from typing import Any, Sequence

from .material_dust import add_dust as add_dust  # noqa: F401 (bproc.material.add_dust)
from .material_library import (change_to_texture_less_render, create_material_from_texture,  # noqa: F401
                               create_new_cc_material, find_cc_material_by_name)
from .session import SESSION
from .types import Material, MeshObject
from .types.unsupported import module_getattr


def collect_all() -> list[Material]:
    """Every material of the session (used or not), in creation order."""
    return [m for m in SESSION.materials if m.is_valid()]


def create(name: str) -> Material:
    """A new Principled material with Blender's defaults (grey 0.8, roughness 0.5)."""
    return Material(name)


def convert_to_materials(blender_materials: Sequence[Any]) -> list[Material | None]:
    """The materials among ``blender_materials`` (they already are hybridgen's; None stays None)."""
    return [m if isinstance(m, Material) else None for m in blender_materials]


def is_material_used(material: Material) -> bool:
    """Whether a mesh object's slot holds ``material``."""
    return any(material in obj.get_materials() for obj in SESSION.entities if isinstance(obj, MeshObject))


__getattr__ = module_getattr("material", [
    "add_alpha", "add_alpha_channel_to_textures", "add_alpha_texture_node", "add_ambient_occlusion",
    "add_base_color", "add_bump", "add_displacement", "add_metal", "add_normal", "add_roughness", "add_specular",
    "connect_uv_maps", "create_image_node"],
    # procedural textures (~15 ms of imports) are imported when first made
    lazy={"create_procedural_texture": "procedural_texture"}, namespace=globals())
