"""``lighting.LightLoader``: lights from config entries (Blender units: W, W/m^2 for the sun)."""
from __future__ import annotations

from typing import Any

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError, closest
from ..scene.frames import object_pose
from ..run.context import RunContext
from ..scene.light import LIGHT_TYPES, Light
from .base import Module, Role

LIGHT_KEYS = {"type": str, "name": str, "location": list, "rotation": list, "color": list, "energy": float,
              "radius": float, "spot_size": float, "spot_blend": float, "size": float}


def light_from_entry(entry: Any, where: str, default_name: str = "light") -> Light:
    """A :class:`Light` from ``{type, name, location [m], rotation [rad, XYZ Euler], color, energy, ...}``."""
    if not isinstance(entry, dict):
        raise ConfigError(f"a light is a mapping, got {entry!r}", key=where)
    for key, value in entry.items():
        if key not in LIGHT_KEYS:
            raise ConfigError(f"unknown light key{closest(key, LIGHT_KEYS)}; known: {list(LIGHT_KEYS)}",
                              key=f"{where}.{key}")
        kind = LIGHT_KEYS[key]
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) if kind is float else \
            isinstance(value, kind)
        sizes = (3, 4) if key == "color" else (3,)  # a color may be RGBA (BlenderProc's); alpha is unused
        if not ok or (kind is list and (len(value) not in sizes or not all(isinstance(v, (int, float))
                                                                            for v in value))):
            raise ConfigError(f"expected {'3 numbers' if kind is list else kind.__name__}, got {value!r}",
                              key=f"{where}.{key}")
    kind = str(entry.get("type", "POINT")).upper()
    if kind not in LIGHT_TYPES:
        raise ConfigError(f"{entry.get('type')!r} is not one of {list(LIGHT_TYPES)}", key=f"{where}.type")
    energy = float(entry.get("energy", 100.0))
    if energy < 0:
        raise ConfigError(f"must be >= 0, got {energy}", key=f"{where}.energy")
    if any(c < 0 for c in entry.get("color", [1, 1, 1])):
        raise ConfigError("channels must be >= 0", key=f"{where}.color")
    optional = {k: float(entry[k]) for k in ("radius", "spot_size", "spot_blend", "size") if k in entry}
    return Light(name=str(entry.get("name", default_name)), type=kind,
                 color=tuple(float(c) for c in entry.get("color", [1.0, 1.0, 1.0])[:3]),  # type: ignore[arg-type]
                 energy=energy, local2world=object_pose(entry.get("location", [0, 0, 0]),
                                                        entry.get("rotation", [0, 0, 0])), **optional)


@register_module("lighting.LightLoader")
class LightLoader(Module):
    """Adds point, spot, sun and area lights; SUN/SPOT/AREA shine along their local -z axis."""

    role = Role.LOADER

    params = (
        Param("lights", "list", sampleable=True,
              doc="entries {type: POINT|SUN|SPOT|AREA, name, location [m], rotation [rad], color [0..], energy [W; "
                  "W/m^2 for SUN], radius [m], spot_size [rad], spot_blend, size [m]}",
              check=lambda v: None if v else "must list at least one light"),
    )

    def run(self, context: RunContext) -> None:
        for index, entry in enumerate(self.value(context, "lights")):
            default_name = f"light_{len(context.scene.lights)}"
            context.scene.add_light(light_from_entry(entry, f"lights[{index}]", default_name))


@register_module("lighting.LightSampler")
class LightSampler(LightLoader):
    """LightLoader whose entries are drawn ``number_of_samples`` times each (samplers give every light its
    own location, color, energy, ...)."""

    role = Role.LOADER

    params = (
        *LightLoader.params,
        Param("number_of_samples", "int", 1, doc="lights drawn per entry",
              check=lambda v: None if v >= 1 else "must be >= 1"),
    )

    def run(self, context: RunContext) -> None:
        for _ in range(self.config["number_of_samples"]):
            super().run(context)
