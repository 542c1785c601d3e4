"""A displacement modifier given in a config (``displace: {...}`` on ``manipulators.EntityManipulator``),
validated key by key into :class:`~hybridgen.scene.displacement.Displacement`."""
from __future__ import annotations

import math
from typing import Any

from ..errors import ConfigError, reject_unknown_keys
from ..input_paths import locate_input
from ..scene.displacement import TEXTURE_COORDS, Displacement
from .schema import closest

KNOWN_KEYS = ("texture", "strength", "mid_level", "subdiv_level", "min_vertices_for_subdiv", "texture_coords")


def displacement_from_config(config: dict[str, Any], key: str = "displace") -> Displacement:
    """The modifier of ``config``; errors name ``<key>.<entry>``."""
    if not isinstance(config, dict):
        raise ConfigError("must be a mapping {texture, strength, mid_level, subdiv_level, ...}", key=key)
    reject_unknown_keys(config, KNOWN_KEYS, key)
    texture = config.get("texture")
    if not isinstance(texture, str) or not texture:
        raise ConfigError("must be the path of a height image (Blender's procedural textures are not available)",
                          key=f"{key}.texture")
    values: dict[str, Any] = {"texture": locate_input(texture)}
    for name in ("strength", "mid_level"):
        if name in config:
            value = config[name]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ConfigError(f"must be a finite number, got {value!r}", key=f"{key}.{name}")
            values[name] = float(value)
    for name, low, high in (("subdiv_level", 0, 8), ("min_vertices_for_subdiv", 0, 2 ** 31)):
        if name in config:
            value = config[name]
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise ConfigError(f"must be an integer in {low}..{high}, got {value!r}", key=f"{key}.{name}")
            values[name] = value
    if "texture_coords" in config:
        coords = str(config["texture_coords"]).upper()
        if coords not in TEXTURE_COORDS:
            raise ConfigError(f"must be one of {', '.join(TEXTURE_COORDS)}, got {config['texture_coords']!r}",
                              key=f"{key}.texture_coords")
        values["texture_coords"] = coords
    return Displacement(**values)
