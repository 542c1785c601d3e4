"""An image blended over a material's base color (BlenderProc 2.8's ``Material.infuse_texture`` into Base Color).

BlenderProc puts, between whatever was linked to the Principled BSDF's Base Color and that input, a MixRGB node:
Color1 the old base color, Color2 an Image Texture node (the image in its own color space, bilinear, repeating)
read at the mesh UV through a Mapping node of type Texture with scale ``texture_scale`` - which divides: the image
repeats every ``texture_scale`` UV units - optionally through an Invert node (``1 - color``). Its factor is the
``strength``. A layer here is that node group; :attr:`hybridgen.scene.material.Material.base_color_layers` holds
them innermost first (a second infuse nests around the first), over the base color the material has without them
(its ``base_color_texture``, vertex colors or value).

The blends are Cycles' (``svm_mix_blend`` / ``svm_mix_overlay`` of ``kernel/svm/mix.h``; the factor clamped to
[0, 1], no clamp of the result, MixRGB's default), per channel on linear RGB, with ``f`` the factor:

- ``MIX``: ``(1 - f) c1 + f c2``;
- ``OVERLAY``: ``c1 (1 - f + 2 f c2)`` where ``c1 < 0.5``, else ``1 - (1 - f + 2 f (1 - c2)) (1 - c1)``.

Which blend a mode gets is BlenderProc's code as it runs, not as its docstring reads: it tests ``mode in
"mix_node"`` (a substring test) before ``mode in "mix"``, so ``mode="mix"`` builds an OVERLAY node and
``mode="overlay"`` keeps the node's default, MIX (:data:`BLEND_OF_MODE`). ``mode="set"`` links the texture alone.
A mesh without UVs reads the texture at UV (0, 0), as Cycles reads a missing UV map.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .gradient_noise import ArrayOps

BLENDS = ("MIX", "OVERLAY")
BLEND_OF_MODE = {"overlay": "MIX", "mix": "OVERLAY"}
"""BlenderProc's ``infuse_texture`` mode -> the blend its MixRGB node gets (see the module docstring)."""


@dataclass(frozen=True)
class ColorLayer:
    """One infused image: ``texture`` (an image path; its pixels decoded from sRGB when ``texture_srgb``, else read
    as stored), ``blend`` (one of :data:`BLENDS`), ``factor`` (the MixRGB factor, clamped to [0, 1] when used),
    ``texture_scale`` (UV units per repeat of the image) and ``invert`` (the image's colors as ``1 - color``)."""

    texture: str
    blend: str = "MIX"
    factor: float = 0.5
    texture_scale: float = 0.05
    invert: bool = False
    texture_srgb: bool = True

    def __post_init__(self) -> None:
        if self.blend not in BLENDS:
            raise ValueError(f"color layer blend must be one of {BLENDS}, got {self.blend!r}")
        if not all(math.isfinite(float(v)) for v in (self.factor, self.texture_scale)):
            raise ValueError(f"color layer factor and texture scale must be finite, got {self.factor}, "
                             f"{self.texture_scale}")

    @property
    def clamped_factor(self) -> float:
        """The factor Cycles uses: clamped to [0, 1]."""
        return min(max(float(self.factor), 0.0), 1.0)

    @property
    def uv_scale(self) -> float:
        """What the UV is multiplied by before the lookup: 1 / ``texture_scale`` (0 for a scale of 0, as Blender's
        safe division in the Mapping node)."""
        return 0.0 if self.texture_scale == 0 else 1.0 / float(self.texture_scale)


def blend_channel(ops: ArrayOps, blend: str, factor: float, base: Any, layer: Any) -> Any:
    """One channel of the MixRGB node: ``base`` (Color1) and ``layer`` (Color2) blended by ``blend`` at ``factor``
    (already clamped)."""
    keep = 1.0 - factor
    if blend == "MIX":
        return keep * base + factor * layer
    if blend == "OVERLAY":
        return ops.select(base < 0.5, base * (keep + 2.0 * factor * layer),
                          1.0 - (keep + 2.0 * factor * (1.0 - layer)) * (1.0 - base))
    raise ValueError(f"unknown blend {blend!r}")


def apply_layer(ops: ArrayOps, layer: ColorLayer, base: tuple[Any, Any, Any],
                texel: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    """The base color (three linear channels) after ``layer``, whose image reads ``texel`` (linear, before the
    inversion) at this point."""
    if layer.invert:
        texel = (1.0 - texel[0], 1.0 - texel[1], 1.0 - texel[2])
    factor = layer.clamped_factor
    r, g, b = (blend_channel(ops, layer.blend, factor, c, t) for c, t in zip(base, texel))
    return r, g, b
