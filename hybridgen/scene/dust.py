"""A dust film over a material (BlenderProc 2.8's ``bproc.material.add_dust``): the surface becomes
``(1 - w) x material + w x dust``, a Lambertian dust BSDF of :data:`DUST_COLOR`, with a weight ``w`` per shading
point computed as the node group BlenderProc builds computes it in Cycles:

1. ``up = clamp(N.z, 0, 1)``: the world-space shading normal's up component (N faces the viewer: a surface seen
   from below has no up component);
2. ``facing = 1 - |cos(view, N)|`` (Layer Weight "Facing", blend 0.5) - a thin rim on silhouettes;
3. ``g = (0.8 up + 0.2 facing) ^ 2.2`` (a Mix at factor 0.2, then Gamma 2.2);
4. the pattern ``T``: Blender's Noise Texture (:mod:`.gradient_noise`; scale 250, detail 0, roughness 0,
   distortion 1.9) of the point ``(u, v, 0) / texture_scale`` in UV space (Texture Coordinate "UV" through a
   Mapping node of type Texture, which divides by its scale; without UVs Cycles reads (0, 0, 0): one value
   everywhere), through a two-stop ramp: 1 (white) below 0.4, 0 (black) above 0.46, linear between (as Cycles'
   256-entry ramp table, interpolated) - flakes.
   With a texture image instead, T is its linear RGB at ``(u, v) / texture_scale`` (bilinear, repeating);
5. ``o = overlay(g, T)``: ``2 g T`` where g < 0.5, else ``1 - 2 (1 - g)(1 - T)`` (per channel; a color becomes
   a number as Cycles converts it, by Rec. 709 luminance);
6. ``w = clamp(strength x o, 0, 1)`` (the Mix Shader clamps its factor).

So an up-facing surface seen head-on (g = 0.8^2.2 = 0.612) gets ``w = strength`` on flakes and
``0.224 x strength`` between them; a vertical or downward surface seen head-on gets none. ``add_dust`` on a
material twice nests a second group around the first: the layers of :attr:`Material.dust` apply in order,
``f = (1 - w_n)(... ((1 - w_1) f + w_1 d_1) ...) + w_n d_n``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .gradient_noise import NUMPY, ArrayOps, noise_texture

DUST_COLOR = (0.8, 0.773, 0.7)
"""Linear RGB base color of BlenderProc's dust BSDF (a Principled BSDF with roughness 1 and Specular IOR Level 0,
i.e. Lambertian)."""
NOISE = {"scale": 250.0, "detail": 0.0, "roughness": 0.0, "distortion": 1.9}
"""The dust pattern's Noise Texture settings."""
RAMP = (0.4, 0.46)
"""The pattern ramp's stops: white (dust) at and below the first, black above the second."""
RAMP_TABLE = 256
"""Entries of the lookup table Cycles bakes a color ramp into."""
UP_SHARE, GAMMA = 0.8, 2.2
LUMINANCE = (0.2126, 0.7152, 0.0722)
"""Rec. 709 luminance weights: Cycles' color -> number conversion in linear sRGB."""
SRGB_SPACES, DATA_SPACES = ("sRGB",), ("Non-Color", "Raw", "Linear")
"""Image color spaces a dust texture may carry: decoded from sRGB, or read as stored."""


def finite_number(value: Any) -> float | None:
    """``value`` as a finite float, or None when it is none."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def reads_as_srgb(colorspace: str) -> bool | None:
    """Whether a texture tagged ``colorspace`` is decoded from sRGB (True) or read as stored (False); None for a
    color space dust textures do not take."""
    if colorspace in SRGB_SPACES:
        return True
    return False if colorspace in DATA_SPACES else None


@dataclass(frozen=True)
class Dust:
    """One dust layer: ``strength`` (0 none, 1 full; above 1 a thicker film), ``texture_scale`` (UV units per
    pattern repeat; smaller is finer), ``texture`` (an image path replacing the noise pattern; its pixels read as
    sRGB when ``texture_srgb``, else as data) and the dust BSDF's linear RGB ``color``."""

    strength: float
    texture_scale: float = 0.1
    texture: str | None = None
    texture_srgb: bool = True
    color: tuple[float, float, float] = DUST_COLOR


def surface_factor(ops: ArrayOps, normal_z: Any, cos_view: Any) -> Any:
    """Steps 1-3: ``g`` from the world up component of the viewer-facing shading normal and the cosine between
    the view direction and that normal."""
    up = ops.clip(normal_z, 0.0, 1.0)
    mixed = UP_SHARE * up + (1.0 - UP_SHARE) * (1.0 - ops.abs(cos_view))
    return ops.power(ops.clip(mixed, 0.0, 1.0), GAMMA)


def pattern_coordinates(ops: ArrayOps, u: Any, v: Any, texture_scale: float) -> tuple[Any, Any]:
    """UV divided by the texture scale (0 for a scale of 0, as Blender's safe division)."""
    inverse = 0.0 if texture_scale == 0 else 1.0 / float(texture_scale)
    return u * inverse, v * inverse


def noise_pattern(ops: ArrayOps, u: Any, v: Any, texture_scale: float) -> Any:
    """Step 4 without a texture: the ramped noise (1 dust flake, 0 none) at the UV point (u, v)."""
    x, y = pattern_coordinates(ops, u, v, texture_scale)
    return ramp(ops, noise_texture(ops, x, y, 0.0 * x, **NOISE))


def ramp(ops: ArrayOps, value: Any) -> Any:
    """The pattern ramp as Cycles evaluates a color ramp: its table of :data:`RAMP_TABLE` entries (the ramp at
    i / (entries - 1)), interpolated linearly."""
    low, high = RAMP
    last = RAMP_TABLE - 1
    position = ops.clip(value, 0.0, 1.0) * float(last)
    index = ops.floor(position)
    t = position - index

    def stop(i: Any) -> Any:
        return ops.clip((high - i * (1.0 / last)) * (1.0 / (high - low)), 0.0, 1.0)

    return (1.0 - t) * stop(index) + t * stop(ops.clip(index + 1.0, 0.0, float(last)))


def overlay(ops: ArrayOps, g: Any, pattern: Any) -> Any:
    """Step 5 for one channel (Blender's Overlay at factor 1)."""
    return ops.select(g < 0.5, 2.0 * g * pattern, 1.0 - 2.0 * (1.0 - g) * (1.0 - pattern))


def layer_weight(ops: ArrayOps, strength: float, g: Any, pattern: Any) -> Any:
    """Step 6 for a gray pattern: the layer's mix weight in [0, 1]."""
    return ops.clip(float(strength) * overlay(ops, g, pattern), 0.0, 1.0)


def layer_weight_rgb(ops: ArrayOps, strength: float, g: Any, rgb: tuple[Any, Any, Any]) -> Any:
    """Step 6 for a color pattern (its three channels): overlay per channel, then luminance."""
    gray = sum(weight * overlay(ops, g, channel) for weight, channel in zip(LUMINANCE, rgb))
    return ops.clip(float(strength) * gray, 0.0, 1.0)


def dust_weight(u: Any, v: Any, normal_z: Any, cos_view: Any, layer: Dust, ops: ArrayOps = NUMPY) -> Any:
    """The mix weight of a noise-pattern ``layer`` at UV (u, v) with world normal up component ``normal_z``
    (viewer-facing) and view cosine ``cos_view``."""
    if layer.texture is not None:
        raise ValueError("dust_weight: a textured layer needs its texture's values (layer_weight_rgb)")
    return layer_weight(ops, layer.strength, surface_factor(ops, normal_z, cos_view),
                        noise_pattern(ops, u, v, layer.texture_scale))


def coefficients(weights: list[Any]) -> tuple[Any, list[Any]]:
    """For nested layers of weights w_1..w_n (innermost first): the material's share prod(1 - w_i) and each
    dust layer's share w_i prod_(j > i)(1 - w_j)."""
    material: Any = 1.0
    shares: list[Any] = []
    for weight in weights:
        shares = [share * (1.0 - weight) for share in shares] + [weight]
        material = material * (1.0 - weight)
    return material, shares
