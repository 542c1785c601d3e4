"""``loader.BlendLoader``: the objects of .blend files, read by Blender's ``bpy`` in its own venv
(:mod:`hybridgen.io.blend_loader`; ``make bpy-venv``), as BlenderProc 1.x's BlendLoader loads them.

BlenderProc's keys: ``path`` or ``paths``; ``obj_types`` (default ``[mesh, empty]``: lights and cameras only
when named, as in BlenderProc; ``light`` adds the file's lights); ``entities`` (a regular expression object
names must match in full); ``datablocks`` (only ``objects`` places anything in the scene: materials, meshes,
images ... are read through the objects that use them); ``add_properties`` (``cp_*`` custom properties).
Meshes keep Blender's names (a name taken in the scene gets the next ``.001``), transforms (metres, world Z up),
custom properties and Principled materials; ``world: true`` (hybridgen's) also takes the file's world background.
"""
from __future__ import annotations

import re
from typing import Any

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.blend_loader import load_blend
from ..io.mesh_loader import unique_blender_name
from ..run.context import RunContext
from ..scene.empty import Empty
from .base import Module, Role
from .obj_loader import add_with_blender_names

OBJ_TYPES = ("mesh", "empty", "light", "camera", "curve", "hair", "armature")


def _types_check(value: Any) -> str | None:
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not all(isinstance(t, str) and t.lower() in OBJ_TYPES for t in items):
        return f"must be one or a list of {', '.join(OBJ_TYPES)}, got {value!r}"
    return None


def _regex_check(value: Any) -> str | None:
    if value is None:
        return None
    try:
        re.compile(value)
    except (re.error, TypeError) as exc:
        return f"is not a regular expression ({exc})"
    return None


@register_module("loader.BlendLoader")
class BlendLoader(Module):
    """Loads the objects of one or more .blend files through Blender's bpy (an optional extra)."""

    role = Role.LOADER

    params = (
        Param("path", "path|null", None, doc=".blend file (relative to the working directory, else the config's folder)"),
        Param("paths", "list|null", None, doc="several .blend files (instead of path)"),
        Param("obj_types", "str|list", ["mesh", "empty"], check=_types_check,
              doc="Blender object types to load (BlenderProc's default: mesh and empty; light adds the lights)"),
        Param("entities", "str|null", None, check=_regex_check, doc="regular expression the object names must match"),
        Param("datablocks", "str|list", "objects", doc="BlenderProc's datablocks; only 'objects' adds to the scene"),
        Param("add_properties", "dict", {}, doc="custom properties for every loaded object (cp_category_id: the class)"),
        Param("cf_merge_objects", "bool", False, doc="BlenderProc's merge: the loaded objects get an empty parent "
              "(cf_merged_object_name) at their mean origin; they stay separate objects (attribute 'parent')"),
        Param("cf_merged_object_name", "str", "merged_object", doc="name of that parent empty"),
        Param("load_from", "str|null", None, doc="not read by BlenderProc 1.12's BlendLoader (a notice)"),
        Param("world", "bool", False, doc="also set the scene's world (background color, strength, HDRI) from the file"),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        if (cfg["path"] is None) == (cfg["paths"] is None):
            raise ConfigError("give path or paths (one of them)", key="path")
        blocks = [cfg["datablocks"]] if isinstance(cfg["datablocks"], str) else list(cfg["datablocks"])
        if "objects" not in blocks:
            notice(f"datablocks {blocks}: only 'objects' places anything in the scene; nothing is loaded",
                   module=self.module_name, index=self.index, key="datablocks")
            return
        if cfg["load_from"] is not None:
            notice("ignored: BlenderProc 1.12's BlendLoader does not read it", module=self.module_name,
                   index=self.index, key="load_from")
        types = [cfg["obj_types"]] if isinstance(cfg["obj_types"], str) else list(cfg["obj_types"])
        skipped = sorted({t.lower() for t in types} - {"mesh", "empty", "light"})
        if skipped:
            notice(f"obj_types {skipped}: hybridgen loads meshes, empties and lights of .blend files",
                   module=self.module_name, index=self.index, key="obj_types")
        for path in [cfg["path"]] if cfg["path"] is not None else cfg["paths"]:
            content = load_blend(str(path), obj_types=types, entities=cfg["entities"])
            for obj in content.objects:
                _add_properties(obj, cfg["add_properties"])
            add_with_blender_names(context, content.objects, renamed=True)
            if cfg["cf_merge_objects"] and content.objects:
                _merge(context, content.objects, cfg["cf_merged_object_name"])
            for light in content.lights:
                context.scene.add_light(light)
            taken = {o.name for o in context.scene.objects} | {e.name for e in context.scene.empties}
            for name, pose in content.empties.items():
                empty = Empty(unique_blender_name(name, taken), pose)
                taken.add(empty.name)
                context.scene.empties.append(empty)
            if cfg["world"] and content.world is not None:
                world = context.scene.world
                world.color, world.strength = content.world["color"], content.world["strength"]
                world.hdri_path = content.world["hdri_path"]


def _add_properties(obj: Any, properties: dict[str, Any]) -> None:
    for key, value in properties.items():
        name = key[3:] if key.startswith("cp_") else key
        if name == "category_id":
            obj.category_id = int(value)
        else:
            obj.attributes[name] = value


def _merge(context: RunContext, objects: list[Any], name: str) -> None:
    """BlenderProc's cf_merge_objects: an empty parent at the objects' mean origin (metres, world frame)."""
    import numpy as np

    pose = np.eye(4)
    pose[:3, 3] = np.mean([o.local2world[:3, 3] for o in objects], axis=0)
    taken = {o.name for o in context.scene.objects} | {e.name for e in context.scene.empties}
    parent = Empty(unique_blender_name(name, taken), pose)
    context.scene.empties.append(parent)
    for obj in objects:
        obj.attributes["parent"] = parent.name
