"""Material values given in a config (``material: {...}`` on loaders), validated key by key."""
from __future__ import annotations

import dataclasses
import math
from typing import Any

from ..errors import ConfigError
from ..scene import principled_inputs
from ..scene.material import ALPHA_MODES, TEXTURE_SLOTS, Material
from ..input_paths import locate_input
from .schema import closest

_UNIT_KEYS = ("roughness", "metallic", "specular", "transmission", "alpha")
_COLOR_KEYS = {"base_color": (3, 4), "emission": (3, 3)}
_TEXTURE_KEYS = TEXTURE_SLOTS
KNOWN_KEYS = (*_UNIT_KEYS, *_COLOR_KEYS, "emission_strength", "ior", *_TEXTURE_KEYS, "name", "alpha_mode",
              "normal_y_down", "displacement_scale", "emission_hidden_from_camera", *principled_inputs.BY_KEY)
"""Config keys: the Material fields and the Principled inputs it keeps in ``extra`` (coat, sheen, subsurface,
anisotropy, specular tint under Blender's names; :mod:`hybridgen.scene.principled_inputs`)."""


def _number(value: Any, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"must be a finite number, got {value!r}", key=f"material.{key}")
    return float(value)


def apply_material_config(material: Material, config: dict[str, Any]) -> Material:
    """A copy of ``material`` with the config's values; errors name ``material.<key>``.

    Overrides replace what they name: a ``base_color`` without a ``base_color_texture`` also removes the
    mesh's own base-color texture (as setting a value on a linked input in BlenderProc unlinks the texture);
    likewise ``roughness``, ``metallic``, ``alpha``, ``specular`` and ``emission`` remove their maps unless the
    map is given too. An ``emission_texture`` without ``emission_strength`` on a material that emits nothing
    gets strength 1 (Blender's default), so the map emits as in Blender.
    """
    values: dict[str, Any] = {}
    extra: dict[str, Any] = {}
    for key, value in config.items():
        if key not in KNOWN_KEYS:
            raise ConfigError(f"unsupported material parameter{closest(key, KNOWN_KEYS)}; supported: "
                              f"{', '.join(KNOWN_KEYS)}", key=f"material.{key}")
        if key in principled_inputs.BY_KEY:
            try:
                extra[key] = principled_inputs.checked(key, value)
            except ValueError as error:
                raise ConfigError(str(error), key=f"material.{key}") from None
        elif key in _UNIT_KEYS:
            number = _number(value, key)
            if not 0.0 <= number <= 1.0:
                raise ConfigError(f"must be in 0..1, got {value!r}", key=f"material.{key}")
            values[key] = number
        elif key in _COLOR_KEYS:
            low, high = _COLOR_KEYS[key]
            if not isinstance(value, list) or not low <= len(value) <= high:
                raise ConfigError(f"must be a list of {low}{'' if low == high else f'-{high}'} numbers",
                                  key=f"material.{key}")
            channels = [_number(v, key) for v in value]
            if any(c < 0 for c in channels) or (key == "base_color" and any(c > 1 for c in channels)):
                raise ConfigError(f"channels must be {'in 0..1' if key == 'base_color' else '>= 0'}, got {value}",
                                  key=f"material.{key}")
            values[key] = tuple(channels + [1.0] * (high - len(channels)))
        elif key == "emission_strength":
            number = _number(value, key)
            if number < 0:
                raise ConfigError(f"must be >= 0, got {value!r}", key=f"material.{key}")
            values[key] = number
        elif key == "displacement_scale":
            values[key] = _number(value, key)
        elif key in ("normal_y_down", "emission_hidden_from_camera"):
            if not isinstance(value, bool):
                raise ConfigError(f"must be true or false, got {value!r}", key=f"material.{key}")
            values[key] = value
        elif key == "alpha_mode":
            if value not in ALPHA_MODES:
                raise ConfigError(f"must be one of {', '.join(ALPHA_MODES)}, got {value!r}", key=f"material.{key}")
            values[key] = value
        elif key == "ior":
            number = _number(value, key)
            if not 1.0 <= number <= 5.0:
                raise ConfigError(f"must be in 1..5, got {value!r}", key=f"material.{key}")
            values[key] = number
        else:
            if not isinstance(value, str) or not value:
                raise ConfigError(f"must be a non-empty string, got {value!r}", key=f"material.{key}")
            values[key] = locate_input(value) if key in _TEXTURE_KEYS else value
    for key in ("base_color", "roughness", "metallic", "alpha", "specular", "emission"):
        if key in values and f"{key}_texture" not in values:
            values[f"{key}_texture"] = None
    if values.get("emission_texture") is not None and "emission_strength" not in values \
            and material.emission_strength == 0:
        values["emission_strength"] = 1.0  # Blender's Emission Strength default, so a given map emits
    if "base_color" in values or values.get("base_color_texture") is not None:
        values["base_color_from_vertices"] = False
        values["missing_files"] = ()  # the mesh's own base-color files are no longer used
    if extra:
        values["extra"] = {**material.extra, **extra}
    return dataclasses.replace(material, **values)
