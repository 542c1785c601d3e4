"""``loader.RockEssentialsRockLoader``: rocks and cliffs of Rock Essentials .blend packs (BlenderProc 1.x's module
of that name), read by Blender's ``bpy`` in its own venv (:mod:`hybridgen.io.blend_loader`; ``make bpy-venv``).

``batches``: one dict per .blend file, with BlenderProc's keys and defaults:

- ``path``: the .blend file; ``objects``: names to load (default: every object whose name holds "Rock" or
  "Cliff"); ``amount``: how many to load (default: as many as there are names; the names repeat in order, or
  are drawn uniformly with ``sample_objects: true``);
- each loaded copy is named ``<name>_<batch index>_<i>`` and gets the attributes ``physics`` (``physics``,
  default false) and category 1, its Subdivision Surface modifier's ``render_levels`` (default 3; the mesh is
  Blender's own subdivision at that level, capped at 3 as BlenderProc's renderer caps it), and ``scale``
  (replacing the object's scale; default [1, 1, 1]);
- ``high_detail_mode``, ``reflection_amount``, ``reflection_roughness``, ``HSV`` set the pack's custom properties
  (``01) High Detail Mode``, ``05) Reflection Amount``, ``06) Reflection Roughness``, ``02) Saturation``,
  ``03) Hue``, ``04) Value``) as attributes. In Blender those drive the pack's node graph; hybridgen reads the
  rock's Principled values as the file stores them, so they do not change the color (a notice says so).
"""
from __future__ import annotations

import copy
import re
from typing import Any

import numpy as np

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import InputError
from ..input_paths import resolve_input
from ..io.blend_loader import load_blend
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from ..scene.frames import matrix_to_euler_xyz, object_pose
from .base import Module, Role

BATCH_KEYS = {"path": str, "objects": list, "amount": int, "sample_objects": bool, "physics": bool,
              "render_levels": int, "high_detail_mode": bool, "scale": list, "reflection_amount": (int, float),
              "reflection_roughness": (int, float), "HSV": list}
ROCK_TYPES = ("Rock", "Cliff")
DRIVEN_KEYS = ("high_detail_mode", "reflection_amount", "reflection_roughness", "HSV")
DRIVEN_PROPERTIES = {"reflection_amount": "05) Reflection Amount", "reflection_roughness": "06) Reflection Roughness"}


def _batches_check(value: Any) -> str | None:
    if not isinstance(value, list):
        return f"must be a list of batch dicts, got {value!r}"
    for i, batch in enumerate(value):
        if not isinstance(batch, dict) or "path" not in batch:
            return f"batch {i} must be a dict with a 'path', got {batch!r}"
        for key, item in batch.items():
            if key not in BATCH_KEYS:
                return f"batch {i}: unknown key '{key}' (known: {', '.join(BATCH_KEYS)})"
            wanted = BATCH_KEYS[key]
            if not isinstance(item, wanted) or (isinstance(item, bool) and wanted in (int, (int, float))):
                return f"batch {i}: '{key}' has the wrong type ({item!r})"
        if batch.get("amount") == 0:
            return f"batch {i}: 'amount' must not be 0 (BlenderProc refuses it too)"
        if "scale" in batch and len(batch["scale"]) != 3:
            return f"batch {i}: 'scale' must be [x, y, z], got {batch['scale']!r}"
        if "HSV" in batch and len(batch["HSV"]) != 3:
            return f"batch {i}: 'HSV' must be [h, s, v], got {batch['HSV']!r}"
    return None


def rock_names(available: list[str], objects: list[str]) -> list[str]:
    """The file's objects a batch may load: those named in ``objects`` (in the file's order), else every rock or
    cliff (by name, as BlenderProc selects them: once per type it matches, Rock first)."""
    if objects:
        return [name for name in available if name in objects]
    return [name for kind in ROCK_TYPES for name in available if kind in name]


def set_scale(obj: MeshObject, scale: list[float]) -> None:
    """Replace ``obj``'s scale (Blender's ``scale``), keeping its location and rotation (world frame)."""
    linear = obj.local2world[:3, :3]
    rotation = matrix_to_euler_xyz(linear / np.linalg.norm(linear, axis=0))
    obj.local2world = object_pose(obj.local2world[:3, 3], rotation, scale)


@register_module("loader.RockEssentialsRockLoader")
class RockEssentialsRockLoader(Module):
    """Loads Rock Essentials rocks from .blend packs through Blender's bpy (module doc)."""

    role = Role.LOADER

    params = (
        Param("batches", "list", [], check=_batches_check, doc="one dict per .blend file (module doc for its keys)"),
    )

    def run(self, context: RunContext) -> None:
        for index, batch in enumerate(self.config["batches"]):
            for obj in self._load_batch(context, index, batch):
                context.scene.add(obj)
        driven = sorted({key for batch in self.config["batches"] for key in DRIVEN_KEYS if key in batch})
        if driven:
            notice(f"{', '.join(driven)} set the pack's custom properties; in Blender they drive its node graph, "
                   "hybridgen renders each rock's stored Principled values", module=self.module_name,
                   index=self.index, key="batches")

    def _load_batch(self, context: RunContext, index: int, batch: dict[str, Any]) -> list[MeshObject]:
        path = resolve_input(batch["path"], f"batches[{index}].path", noun=".blend file")
        wanted = list(batch.get("objects", []))
        pattern = "|".join(re.escape(n) for n in wanted) if wanted else ".*(" + "|".join(ROCK_TYPES) + ").*"
        content = load_blend(path, obj_types=["mesh"], entities=pattern,
                             render_levels=int(batch.get("render_levels", 3)))
        parts: dict[str, list[MeshObject]] = {}
        for obj in content.objects:
            parts.setdefault(obj.name, []).append(obj)
        names = rock_names(sorted(parts, key=str.casefold), wanted)
        if not names:
            raise InputError(f"{self.module_name}: '{path}' has no object "
                             + (f"named {wanted}" if wanted else "with Rock or Cliff in its name"))
        amount = batch.get("amount")
        count = len(names) if amount is None else int(amount)
        sample = bool(batch.get("sample_objects", False)) and amount is not None
        loaded = []
        for i in range(count):
            name = names[int(context.rng.integers(len(names)))] if sample else names[i % len(names)]
            for part in parts[name]:
                obj = copy.deepcopy(part)
                obj.name = f"{name}_{index}_{i}"
                self._set_properties(obj, batch)
                loaded.append(obj)
        return loaded

    def _set_properties(self, obj: MeshObject, batch: dict[str, Any]) -> None:
        obj.attributes["physics"] = bool(batch.get("physics", False))
        obj.category_id = 1
        set_scale(obj, list(batch.get("scale", [1.0, 1.0, 1.0])))
        if "01) High Detail Mode" in obj.attributes:
            obj.attributes["01) High Detail Mode"] = bool(batch.get("high_detail_mode", False))
        for key, prop in DRIVEN_PROPERTIES.items():
            if key in batch:
                obj.attributes[prop] = float(batch[key])
        if "HSV" in batch:
            hue, saturation, value = (float(v) for v in batch["HSV"])
            obj.attributes.update({"02) Saturation": saturation, "03) Hue": hue, "04) Value": value})
