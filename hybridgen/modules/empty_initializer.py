"""``constructor.BasicEmptyInitializer``: named poses without geometry (Blender empties), as BlenderProc adds them.

Each ``empties_to_add`` entry: ``name`` (required; a taken name gets Blender's next ``.001``), ``type`` (Blender's
display type, default ``plain_axes``; it changes nothing else), ``location`` (m), ``rotation`` (Blender XYZ Euler,
rad), ``scale`` (default 1). Values may be samplers. The empties go to ``Scene.empties`` (:mod:`hybridgen.scene.empty`):
never drawn, not in ``object_states``; ``depth_of_field.focal_object`` selects them by name or attributes.
"""
from __future__ import annotations

from typing import Any

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError, HybridgenError, reject_unknown_keys
from ..io.mesh_loader import unique_blender_name
from ..run.context import RunContext
from ..scene.empty import EMPTY_TYPES, Empty
from ..scene.frames import object_pose
from .base import Module, Role

ENTRY_KEYS = ("name", "type", "location", "rotation", "scale")


def _vector(value: Any, key: str, default: list[float]) -> list[float]:
    if value is None:
        return default
    if isinstance(value, (int, float)) and not isinstance(value, bool) and key.endswith("scale"):
        return [float(value)] * 3
    if not isinstance(value, (list, tuple)) or len(value) != 3 or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise ConfigError(f"must be three numbers, got {value!r}", key=key)
    return [float(v) for v in value]


@register_module("constructor.BasicEmptyInitializer")
class BasicEmptyInitializer(Module):
    """Adds empties (named poses without geometry) to the scene."""

    role = Role.LOADER

    params = (
        Param("empties_to_add", "list", sampleable=True, doc="entries {name, type (plain_axes, arrows, "
              "single_arrow, circle, cube, sphere, cone), location [m], rotation [rad, Blender XYZ Euler], "
              "scale}"),
    )

    def run(self, context: RunContext) -> None:
        entries = self.value(context, "empties_to_add")
        scene = context.scene
        for index, entry in enumerate(entries):
            where = f"empties_to_add[{index}]"
            if not isinstance(entry, dict):
                raise ConfigError("an empty is a mapping {name, type, location, rotation, scale}", key=where)
            reject_unknown_keys(entry, ENTRY_KEYS, where)
            name = entry.get("name")
            if not isinstance(name, str) or not name:
                raise ConfigError("every empty needs a name", key=f"{where}.name")
            kind = str(entry.get("type", "plain_axes")).lower()
            if kind not in EMPTY_TYPES:
                raise ConfigError(f"type {entry.get('type')!r} is not one of {list(EMPTY_TYPES)}", key=f"{where}.type")
            try:
                pose = object_pose(_vector(entry.get("location"), f"{where}.location", [0.0, 0.0, 0.0]),
                                   _vector(entry.get("rotation"), f"{where}.rotation", [0.0, 0.0, 0.0]),
                                   _vector(entry.get("scale"), f"{where}.scale", [1.0, 1.0, 1.0]))
            except ConfigError:
                raise
            except HybridgenError as exc:
                raise ConfigError(str(exc), key=where) from None
            taken = {o.name for o in scene.objects} | {e.name for e in scene.empties}
            scene.empties.append(Empty(unique_blender_name(name, taken), pose, kind))
