"""``bproc.loader.load_blend``: the objects of a .blend file (BlenderProc's BlendLoader), read by Blender's
``bpy`` in a child process (:mod:`hybridgen.io.blend_loader`; ``make bpy-venv`` installs it).

As BlenderProc: ``obj_types`` (default mesh and empty; lower-cased, one name or a list) picks the object types,
``name_regrex`` is a regular expression the whole object name must match, and the objects come back as
``bproc.types`` entities (MeshObject, Light, or Entity for an empty) with Blender's names, poses, parents,
render visibility, custom properties (``category_id`` too), Principled BSDF values and image textures. Types
and data blocks hybridgen's scene model has no counterpart for (cameras, curves, armatures ...; data blocks
other than ``objects``) raise one line naming the call; ``link`` changes nothing hybridgen renders.
"""
from __future__ import annotations

import re
from typing import Any

from ..errors import InputError
from .loader_support import group_parts, to_mesh_objects
from .types import Entity, Light, Material
from .types.unsupported import fail
from .utility import resolve_path

BLENDER_OBJECT_TYPES = ("mesh", "curve", "curves", "surface", "meta", "font", "hair", "pointcloud", "volume",
                        "gpencil", "armature", "lattice", "empty", "light", "light_probe", "camera", "speaker")
"""Blender's object types (``bpy.types.Object.type``, lower-cased), as BlenderProc validates ``obj_types``."""
LOADED_TYPES = ("mesh", "empty", "light")
BLENDER_DATA_BLOCKS = ("actions", "armatures", "brushes", "cache_files", "cameras", "collections", "curves",
                       "fonts", "grease_pencils", "hair_curves", "images", "lattices", "libraries", "lightprobes",
                       "lights", "linestyles", "masks", "materials", "meshes", "metaballs", "movieclips",
                       "node_groups", "objects", "paint_curves", "palettes", "particles", "pointclouds",
                       "scenes", "screens", "shape_keys", "sounds", "speakers", "texts", "textures", "volumes",
                       "window_managers", "workspaces", "worlds")
"""``bpy.data``'s collections, the data blocks BlenderProc accepts."""


def _listed(value: Any, allowed: tuple[str, ...], what: str) -> list[str]:
    items = [value] if isinstance(value, str) else list(value)
    lowered = [str(item).lower() for item in items]
    for item in lowered:
        if item not in allowed:
            raise InputError(f"bproc.loader.load_blend: No such {what}: {item}")
    return lowered


def load_blend(path: str, obj_types: list[str] | str | None = None, name_regrex: str | None = None,
               data_blocks: list[str] | str = "objects", link: bool = False) -> list[Entity]:
    """The entities of the .blend file ``path`` (see the module documentation)."""
    from ..io.blend_loader import load_blend as read_blend

    types = _listed(["mesh", "empty"] if obj_types is None else obj_types, BLENDER_OBJECT_TYPES, "object type")
    blocks = _listed(data_blocks, BLENDER_DATA_BLOCKS, "data block")
    if blocks != ["objects"]:
        fail(f"bproc.loader.load_blend(data_blocks={[b for b in blocks if b != 'objects']})",
             "hybridgen loads the objects of a .blend file")
    other = [t for t in types if t not in LOADED_TYPES]
    if other:
        fail(f"bproc.loader.load_blend(obj_types={other})", "hybridgen loads meshes, empties and lights")
    if name_regrex:
        try:
            re.compile(name_regrex)
        except re.error as exc:
            raise InputError(f"bproc.loader.load_blend: name_regrex {name_regrex!r} is no regular expression: "
                             f"{exc}") from None
    content = read_blend(resolve_path(path), obj_types=types, entities=name_regrex or None)
    # created in the order of the file's object list (sorted by name), as Blender appends them
    items: list[tuple[str, str, Any]] = [(group[0].name, "mesh", group) for group in group_parts(content.objects)]
    items += [(light.name, "light", light) for light in content.lights]
    items += [(name, "empty", pose) for name, pose in content.empties.items()]
    materials: dict[int, Material] = {}
    loaded: dict[str, Entity] = {}  # by the file's names (the session may have given Blender's next suffix)
    for name, kind, data in sorted(items, key=lambda item: item[0]):
        if name in loaded:
            continue
        if kind == "mesh":
            loaded[name] = to_mesh_objects(data, materials, skipped=("source_path",))[0]
        elif kind == "light":
            light = Light(data.type, name)
            light.set_energy(data.energy)
            light.set_color(data.color)
            light.set_radius(data.radius)
            light.set_local2world_mat(data.local2world)
            loaded[name] = light
        else:
            loaded[name] = Entity(name, data)
    for child, parent in content.parents.items():
        if child in loaded and parent in loaded:
            loaded[child].set_parent(loaded[parent])
    for name in content.hidden:
        if name in loaded:
            loaded[name].hide(True)
    return list(loaded.values())
