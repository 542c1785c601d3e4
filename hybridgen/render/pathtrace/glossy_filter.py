"""Filter glossy (Cycles' ``blur_glossy``): glossy lobes roughened after rough bounces, against fireflies.

A sharp highlight seen through a diffuse bounce (floor -> glossy mug -> lamp) is a caustic path: a diffuse
BSDF sample rarely finds the narrow lobe, and when it does the sample is very bright. Cycles regularizes
such paths by default (``blur_glossy`` 1.0, which BlenderProc keeps): it tracks the smallest BSDF-sampling
pdf of the path so far, ``min_ray_pdf``, and at every later vertex with ``blur_pdf = min_ray_pdf / blur_glossy
< 1`` raises each microfacet lobe's alpha to at least ``sqrt(1 - blur_pdf) / 2`` (Cycles' scene sync stores
``1 / blur_glossy`` as the kernel's ``filter_glossy``, which multiplies ``min_ray_pdf``: a larger
``blur_glossy`` blurs more). After a diffuse bounce (pdf cos / pi <= 0.32) that is alpha >= 0.41 (roughness >=
0.64); camera rays and paths that only followed sharp lobes are untouched. It is a bias (indirectly seen highlights are blurred) traded for
much less noise; ``filter_glossy: 0`` turns it off.

hybridgen does the same in its path tracer (:mod:`hybridgen.render.pathtrace.clamped_path`, JIT variants): the
roughness of every principled BSDF is wrapped in :data:`PLUGIN_NAME` (parameters ``value`` or ``map``, the
roughness texture), a texture that returns
``max(roughness, floor)``, and the integrator passes each vertex's roughness floor (``sqrt(alpha)``: Mitsuba's
and Blender's alpha is roughness squared) in the surface interaction's ``time`` field, which nothing else
reads for static scenes (hybridgen has no motion blur). Renders that do not set it (AOVs, Mitsuba's own
integrators, camera vertices) see time 0: the plain roughness. Measured on the tabletop scene of
tools/color_quality.py (160x120, glossy/transmission bounces 0, no denoising, PSNR against each engine's
2048-spp reference): Cycles itself at 64 / 256 spp 44.8 / 50.2 dB with blur_glossy 1, 43.2 / 48.8 dB with
0 - the gap hybridgen had before this filter.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

from .mitsuba_variant import is_jit

PLUGIN_NAME = "hybridgen_filtered_roughness"
DEFAULT_FILTER_GLOSSY = 1.0
"""Cycles' default ``blur_glossy`` (BlenderProc keeps it)."""


def roughness_floor(filter_glossy: float, min_ray_pdf: Any) -> Any:
    """Principled roughness floor (Dr.Jit Float) of a vertex whose path's smallest BSDF-sampling pdf so far is
    ``min_ray_pdf`` (sr^-1; +inf for camera vertices): sqrt of Cycles' alpha floor ``sqrt(1 - blur_pdf) / 2`` with
    ``blur_pdf = min_ray_pdf / filter_glossy`` (``filter_glossy`` > 0: Cycles' ``blur_glossy``)."""
    import drjit as dr

    blur_pdf = min_ray_pdf / filter_glossy
    return dr.select(blur_pdf < 1.0, dr.sqrt(dr.sqrt(dr.maximum(1.0 - blur_pdf, 0.0)) * 0.5), 0.0)


def filtered_roughness(roughness: Any) -> Any:
    """The principled BSDF's ``roughness`` input (a value or a texture dictionary) wrapped so that the path
    tracer can raise it (JIT variants; ``scalar_rgb`` keeps the plain input)."""
    import mitsuba as mi

    variant = mi.variant()
    if not variant or not is_jit(variant):
        return roughness
    register(variant)
    if isinstance(roughness, dict):
        return {"type": PLUGIN_NAME, "map": roughness}
    return {"type": PLUGIN_NAME, "value": float(roughness)}


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register the wrapping texture for ``variant`` (the active JIT variant)."""
    import drjit as dr
    import mitsuba as mi

    class FilteredRoughness(mi.Texture):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.inner = props.get("map") if "map" in props else None
            self.value = mi.Float(props.get("value", 0.5))

        def eval_1(self, si: Any, active: Any = True) -> Any:
            base = self.inner.eval_1(si, active) if self.inner is not None else self.value
            return dr.maximum(base, si.time)

        def mean(self) -> float:
            return float(self.inner.mean()) if self.inner is not None else float(self.value[0])

        def traverse(self, callback: Any) -> None:  # mi.traverse: "<bsdf>.roughness.value" / ".map.data"
            if self.inner is not None:
                callback.put("map", self.inner, mi.ParamFlags.Differentiable)
            else:
                callback.put("value", self.value, mi.ParamFlags.Differentiable)

        def parameters_changed(self, keys: Any = None) -> None:
            pass

        def is_spatially_varying(self) -> bool:
            return True

        def to_string(self) -> str:
            return f"FilteredRoughness[{self.inner if self.inner is not None else self.value[0]}]"

    mi.register_texture(PLUGIN_NAME, lambda props: FilteredRoughness(props))
