"""A config's infused image (``manipulators.MaterialManipulator``'s ``infuse_texture``, BlenderProc 1.x's
``cf_infuse_texture``) applied to a material: ``{texture, mode: overlay, connection: Base Color, strength: 0.5,
texture_scale: 0.05, invert_texture: false}``, where ``texture`` is an image path or a list of them
(``getter.Texture``'s result, BlenderProc's ``used_texture``; one is drawn, as BlenderProc draws one) read as sRGB
unless the scene's texture of that path is tagged otherwise. Semantics: :mod:`hybridgen.scene.infused_texture`."""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import ConfigError
from ..scene.dust import DATA_SPACES, SRGB_SPACES, reads_as_srgb
from ..scene.image_texture import ImageTexture
from ..scene.infused_texture import InfuseError, infuse_texture
from ..scene.material import Material

KEYS = ("texture", "mode", "connection", "strength", "texture_scale", "invert_texture")


def _texture(value: Any, rng: np.random.Generator, textures: Sequence[ImageTexture]) -> tuple[str, bool]:
    """(path, decoded from sRGB) of the configured texture (a list is drawn from with ``rng``)."""
    if isinstance(value, (list, tuple)):
        if not value:
            raise ConfigError("You have to select a texture, which is infused into the material (an empty list)",
                              key="infuse_texture.texture")
        value = value[int(rng.integers(len(value)))]
    if value is None:
        raise ConfigError("You have to select a texture, which is infused into the material",
                          key="infuse_texture.texture")
    path = Path(str(value))
    if not path.is_file():
        raise ConfigError(f"no such image file: {path}", key="infuse_texture.texture")
    spaces = [t.colorspace for t in textures if Path(t.path).resolve() == path.resolve()] or ["sRGB"]
    srgb = reads_as_srgb(spaces[0])
    if srgb is None:
        raise ConfigError(f"a texture in color space {spaces[0]!r} is not supported (supported: "
                          f"{', '.join(SRGB_SPACES + DATA_SPACES)})", key="infuse_texture.texture")
    return str(path), srgb


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
    path, srgb = _texture(value.get("texture"), rng, textures)
    out = dataclasses.replace(material, extra=dict(material.extra))
    try:
        infuse_texture(out, path, srgb, mode, str(value.get("connection", "Base Color")),
                       value.get("texture_scale", 0.05), value.get("strength", 0.5),
                       bool(value.get("invert_texture", False)))
    except InfuseError as error:
        raise ConfigError(str(error), key="infuse_texture") from None
    return out
