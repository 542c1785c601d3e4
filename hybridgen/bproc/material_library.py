"""``bproc.material``'s helpers that make, find or swap whole materials (BlenderProc 2.8's MaterialLoaderUtility):
``create_material_from_texture``, ``create_new_cc_material``, ``find_cc_material_by_name`` and
``change_to_texture_less_render``, with BlenderProc's semantics over hybridgen's materials."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import InputError
from ..scene.material import TEXTURE_SLOTS
from .bpy_standin import Image
from .session import SESSION
from .types import Material, MeshObject

TEXTURE_LESS = {"Specular IOR Level": 0.65, "Roughness": 0.2}
"""The Principled inputs of ``change_to_texture_less_render``'s material (the rest Blender's defaults)."""


def create_material_from_texture(texture: str | Path | Any, material_name: str) -> Material:
    """A new material named ``material_name`` whose Base Color is the image ``texture`` (a path, or an image such as
    ``bpy.data.images.load`` gives)."""
    call = "bproc.material.create_material_from_texture"
    if isinstance(texture, (str, Path)):
        if not Path(texture).exists():
            raise InputError(f'{call}: The given texture path could not be found: "{texture}"')
        texture = Image(str(texture))
    elif not hasattr(texture, "filepath"):
        raise InputError(f"{call}: The given type of texture must be either [str, Path, bpy.types.Image] and not "
                         f"{type(texture)}.")
    material = Material(material_name)
    material.set_principled_shader_value("Base Color", texture)
    return material


def create_new_cc_material(material_name: str, add_custom_properties: dict[str, Any]) -> Material:
    """A new default material named ``material_name`` with the custom properties ``is_cc_texture`` (True),
    ``asset_name`` (the name) and ``add_custom_properties`` (keys ``cp_<name>``)."""
    material = Material(material_name)
    material.set_cp("is_cc_texture", True)
    material.set_cp("asset_name", material_name)
    for key, value in add_custom_properties.items():
        if not key.startswith("cp_"):
            raise InputError("bproc.material.create_new_cc_material: All cp have to start with cp_")
        material.set_cp(key[len("cp_"):], value)
    return material


def find_cc_material_by_name(material_name: str, custom_properties: dict[str, Any]) -> Material | None:
    """The one material made by :func:`create_new_cc_material` for ``material_name`` whose custom properties
    also match ``custom_properties`` (keys ``cp_<name>``); None when there is none, one line when there are more."""
    conditions = {"is_cc_texture": True, "asset_name": material_name}
    for key, value in custom_properties.items():
        if not key.startswith("cp_"):
            raise InputError(f"bproc.material.find_cc_material_by_name: condition {key!r} is not supported by "
                             "hybridgen yet (custom properties cp_<name> are)")
        conditions[key[len("cp_"):]] = value
    found = [material for material in SESSION.materials if material.is_valid()
             and all(material.has_cp(key) and material.get_cp(key) == value for key, value in conditions.items())]
    if len(found) > 1:
        raise InputError("bproc.material.find_cc_material_by_name: There was more than one material found!")
    return found[0] if found else None


def _emits(material: Material) -> bool:
    """Whether the material emits light (what BlenderProc's Emission shader node does: ``make_emissive``,
    ``light_surface`` and the dataset loaders' lamps)."""
    mat = material.blender_obj
    return mat.emission_strength > 0 and (max(mat.emission) > 0 or mat.emission_texture is not None)


def _has_png_image(material: Material) -> bool:
    """Whether an image node of ``material``'s tree shows a .png (BlenderProc tests ``'.png' in image.name``):
    every image input (:data:`~hybridgen.scene.material.TEXTURE_SLOTS`) and the infused images; not dust's, whose
    nodes sit in a node group BlenderProc's loop does not enter."""
    mat = material.blender_obj
    paths = [getattr(mat, slot) for slot in TEXTURE_SLOTS] + [layer.texture for layer in mat.base_color_layers]
    return any(isinstance(path, (str, Path)) and ".png" in Path(path).name for path in paths)


def change_to_texture_less_render(use_alpha_channel: bool) -> None:
    """Every material slot of every mesh object whose material does not emit gets one new material ``TextureLess``
    (Specular IOR Level 0.65, Roughness 0.2, Blender's default gray). With ``use_alpha_channel``, a material with a
    .png image gets a copy of it instead (``TextureLess.001`` ...), as BlenderProc makes one - whose image node
    BlenderProc leaves unlinked, so it renders the same."""
    texture_less = Material("TextureLess")
    for name, value in TEXTURE_LESS.items():
        texture_less.set_principled_shader_value(name, value)
    for obj in [entity for entity in SESSION.entities if isinstance(entity, MeshObject) and entity.is_valid()]:
        for index, material in enumerate(obj.get_materials()):
            if material is None:
                continue  # a slot without a material (BlenderProc's loop fails on it)
            if _emits(material):
                continue
            use = texture_less.duplicate() if use_alpha_channel and _has_png_image(material) else texture_less
            obj.set_material(index, use)
