"""A config's infused image (``manipulators.MaterialManipulator``'s ``infuse_texture``, BlenderProc 1.x's
``cf_infuse_texture``) applied to a material: ``{texture, mode: overlay, connection: Base Color, strength: 0.5,
texture_scale: 0.05, invert_texture: false}``, where ``texture`` is an image path or a list of them
(``getter.Texture``'s result, BlenderProc's ``used_texture``; one is drawn, as BlenderProc draws one) read as sRGB
unless the scene's texture of that path is tagged otherwise. Semantics: :mod:`hybridgen.scene.infused_texture`."""
from __future__ import annotations

import dataclasses
from typing import Any, Sequence

import numpy as np

from ..errors import ConfigError
from ..scene.image_texture import ImageTexture
from ..scene.infused_texture import InfuseError, infuse_texture
from ..scene.material import Material
from .drawn_texture import drawn_texture

KEYS = ("texture", "mode", "connection", "strength", "texture_scale", "invert_texture")


def infused(material: Material, value: dict[str, Any], rng: np.random.Generator,
            textures: Sequence[ImageTexture] = ()) -> Material:
    """A copy of ``material`` with the image of a config's ``infuse_texture`` mapping infused."""
    if not isinstance(value, dict):
        raise ConfigError("must be a mapping with texture (and mode, connection, strength, texture_scale, "
                          "invert_texture)", key="infuse_texture")
    unknown = sorted(set(value) - set(KEYS))
    if unknown:
        raise ConfigError(f"unknown key(s) {unknown} (known: {', '.join(KEYS)})", key="infuse_texture")
    mode = str(value.get("mode", "overlay"))
    if "strength" in value and mode.lower() == "set":
        raise ConfigError('The strength can only be used if the mode is not "set"!', key="infuse_texture.strength")
    drawn = drawn_texture(value.get("texture"), rng, textures, "infuse_texture.texture",
                          "You have to select a texture, which is infused into the material (an empty list)",
                          "a texture")
    if drawn is None:
        raise ConfigError("You have to select a texture, which is infused into the material",
                          key="infuse_texture.texture")
    path, srgb = drawn
    out = dataclasses.replace(material, extra=dict(material.extra))
    try:
        infuse_texture(out, path, srgb, mode, str(value.get("connection", "Base Color")),
                       value.get("texture_scale", 0.05), value.get("strength", 0.5),
                       bool(value.get("invert_texture", False)))
    except InfuseError as error:
        raise ConfigError(str(error), key="infuse_texture") from None
    return out
