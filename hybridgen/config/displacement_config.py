"""A displacement modifier given in a config (``displace: {...}`` on ``manipulators.EntityManipulator``; BlenderProc
1.x's ``cf_add_displace_modifier_with_texture`` translates to it), validated key by key into
:class:`~hybridgen.scene.displacement.Displacement`.

``texture`` is what BlenderProc's modifier takes: a procedural texture of ``sampler.Texture``
(:mod:`hybridgen.sampling.texture_sampler`), the name of one (``CLOUDS``, ``VORONOI``, ... with Blender's
defaults: BlenderProc documents this form, though Blender itself rejects a string there), or an image - a path,
e.g. from ``getter.Texture`` over ``loader.TextureLoader``'s textures (their ``colorspace`` comes along; a plain
path is tagged sRGB as Blender tags a loaded file) - read as Blender's Displace modifier reads an image
(:class:`~hybridgen.scene.displacement_texture.ImageHeight`).
"""
from __future__ import annotations

import math
from typing import Any, Iterable

from ..errors import ConfigError, reject_unknown_keys
from ..input_paths import locate_input
from ..scene.displacement import Displacement
from ..scene.displacement_texture import ImageHeight, ProceduralHeight, Texture
from ..scene.procedural_texture import TYPES

KNOWN_KEYS = ("texture", "strength", "mid_level", "subdiv_level", "min_vertices_for_subdiv", "texture_coords")
CONFIG_COORDS = ("LOCAL", "UV")
"""Texture coordinates a config may choose (GLOBAL would read the pose at manipulation, not at render time)."""


def _texture(value: Any, key: str, textures: Iterable[Any]) -> Texture:
    if isinstance(value, list) and len(value) == 1:  # getter.Texture without index: a one-element list
        value = value[0]
    if isinstance(value, ProceduralHeight):
        return value
    if isinstance(value, str) and value.upper() in TYPES and value == value.upper():
        return ProceduralHeight.of(value)
    if not isinstance(value, str) or not value:
        raise ConfigError("must be a texture of sampler.Texture, a procedural texture name "
                          f"({', '.join(TYPES)}) or the path of a height image, got {value!r}", key=key)
    path = locate_input(value)
    tags = {str(t.path): t.colorspace for t in textures if hasattr(t, "path") and hasattr(t, "colorspace")}
    return ImageHeight(path, tags.get(str(path), tags.get(value, "sRGB")))


def displacement_from_config(config: dict[str, Any], key: str = "displace",
                             textures: Iterable[Any] = ()) -> Displacement:
    """The modifier of ``config``; errors name ``<key>.<entry>``. ``textures``: the scene's loaded image textures,
    whose colorspace an image path of theirs takes."""
    if not isinstance(config, dict):
        raise ConfigError("must be a mapping {texture, strength, mid_level, subdiv_level, ...}", key=key)
    reject_unknown_keys(config, KNOWN_KEYS, key)
    values: dict[str, Any] = {"texture": _texture(config.get("texture"), f"{key}.texture", textures)}
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
        if coords not in CONFIG_COORDS:
            raise ConfigError(f"must be one of {', '.join(CONFIG_COORDS)}, got {config['texture_coords']!r}",
                              key=f"{key}.texture_coords")
        values["texture_coords"] = coords
    return Displacement(**values)
