"""A config's dust film (``manipulators.MaterialManipulator``'s ``dust``, BlenderProc 1.x's ``cf_add_dust``) as a
:class:`~hybridgen.scene.dust.Dust` layer on a material: ``{strength, texture_scale: 0.1, texture: null}``, where
``texture`` is an image path or a list of them (``getter.Texture``'s result; one is drawn, as BlenderProc draws
one of its textures) read as sRGB unless the scene's texture of that path is tagged otherwise."""
from __future__ import annotations

import dataclasses
from typing import Any, Sequence

import numpy as np

from ..errors import ConfigError
from ..scene.dust import Dust, finite_number
from ..scene.image_texture import ImageTexture
from ..scene.material import Material
from .drawn_texture import drawn_texture

KEYS = ("strength", "texture_scale", "texture")


def _number(value: Any, key: str) -> float:
    number = finite_number(value)
    if number is None:
        raise ConfigError(f"must be a finite number, got {value!r}", key=f"dust.{key}")
    return number


def dust_layer(value: dict[str, Any], rng: np.random.Generator, textures: Sequence[ImageTexture] = ()) -> Dust:
    """The layer a config's ``dust`` mapping describes (a path list is drawn from with ``rng``)."""
    if not isinstance(value, dict) or "strength" not in value:
        raise ConfigError("must be a mapping with strength (and texture_scale, texture)", key="dust")
    unknown = sorted(set(value) - set(KEYS))
    if unknown:
        raise ConfigError(f"unknown key(s) {unknown} (known: {', '.join(KEYS)})", key="dust")
    drawn = drawn_texture(value.get("texture"), rng, textures, "dust.texture", "is an empty list of textures",
                          "a dust texture")
    texture, srgb = drawn if drawn is not None else (None, True)
    return Dust(_number(value["strength"], "strength"), _number(value.get("texture_scale", 0.1), "texture_scale"),
                texture, srgb)


def with_dust(material: Material, layer: Dust) -> Material:
    """A copy of ``material`` with ``layer`` over its dust films."""
    return dataclasses.replace(material, dust=(*material.dust, layer), extra=dict(material.extra))
