"""``sampler.Texture``: a new Blender procedural texture, as BlenderProc 1.x's sampler creates one for
EntityManipulator's displacement (``cf_add_displace_modifier_with_texture``, hybridgen's ``displace.texture``).

The type is drawn uniformly from ``textures`` (any case), or from BlenderProc's nine (CLOUDS, DISTORTED_NOISE,
MAGIC, MARBLE, MUSGRAVE, NOISE, STUCCI, VORONOI, WOOD) when none are given - with the run's generator where
BlenderProc uses Python's ``random``. The texture has Blender 4.2's defaults; a VORONOI one takes
``noise_scale`` (0.25), ``noise_intensity`` (1.0) and ``nabla`` (0.03), as BlenderProc sets them (the other
types ignore them, as BlenderProc does). The value is a
:class:`~hybridgen.scene.displacement_texture.ProceduralHeight` (:mod:`hybridgen.scene.procedural_texture`
evaluates it).
"""
from __future__ import annotations

from typing import Any, Sequence

from ..scene.displacement_texture import ProceduralHeight
from ..scene.procedural_texture import TYPES
from .sampler_table import DrawContext, register_sampler

PATTERNS = ("CLOUDS", "DISTORTED_NOISE", "MAGIC", "MARBLE", "MUSGRAVE", "NOISE", "STUCCI", "VORONOI", "WOOD")
"""BlenderProc 1.x's sampler.Texture types, in its order."""


def _check(p: dict[str, Any]) -> None:
    given = p.get("textures") or []
    if not isinstance(given, (list, tuple)):
        raise ValueError(f"textures must be a list of texture types, got {given!r}")
    for name in given:
        if str(name).upper() not in TYPES:
            raise ValueError(f"there is no procedural texture {name!r} (Blender's: {', '.join(TYPES)})")


@register_sampler("sampler.Texture", "TextureSampler", validate=_check)
def texture(ctx: DrawContext, textures: Sequence[str] = (), noise_scale: float = 0.25, noise_intensity: float = 1.0,
            nabla: float = 0.03) -> ProceduralHeight:
    """A procedural texture of a type drawn from ``textures`` (default: BlenderProc's nine; module doc)."""
    _check({"textures": list(textures)})
    pool = [str(name).upper() for name in textures] or list(PATTERNS)
    kind = pool[int(ctx.rng.integers(len(pool)))]
    if kind == "VORONOI":
        return ProceduralHeight.of(kind, noise_scale=float(noise_scale), noise_intensity=float(noise_intensity),
                                   nabla=float(nabla))
    return ProceduralHeight.of(kind)
