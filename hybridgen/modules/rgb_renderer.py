"""``renderer.RgbRenderer``: path-traced color with Mitsuba 3, plus any label passes from the raster view."""
from __future__ import annotations

from typing import Any

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..render.mitsuba_variant import choose_variant
from ..render.path_trace import PathTraceSettings
from ..render.render_color import render_color
from ..run.context import RunContext
from .base import Module
from .label_params import label_params, label_request


def _non_negative(value: Any) -> str | None:
    return None if value >= 0 else f"must be >= 0, got {value}"


@register_module("renderer.RgbRenderer")
class RgbRenderer(Module):
    """Renders color for every keypoint; render_depth / render_normals / map_by add labels in the same pass."""

    params = (
        Param("samples", "int", 64, "spp", "samples per pixel", check=positive),
        Param("min_bounces", "int", 1, doc="bounces before Russian roulette may end a path (Cycles' meaning)",
              check=_non_negative),
        Param("max_bounces", "int", 8, doc="indirect bounces, 0 = direct light only (Mitsuba max_depth = "
              "max_bounces + 2)", check=_non_negative),
        Param("glossy_bounces", "int|null", None, doc="must be >= max_bounces if given: Mitsuba has one depth "
              "limit for all lobes", check=lambda v: None if v is None else _non_negative(v)),
        Param("resolution_x", "int|null", None, "px", "overrides the camera width (K scaled)"),
        Param("resolution_y", "int|null", None, "px", "overrides the camera height (K scaled)"),
        Param("output_hdr", "bool", False, doc="also write linear colors_hdr (float16)"),
        Param("denoise", "bool", False, doc="Open Image Denoise (needs pyoidn) guided by the raster albedo and "
              "normals; colors_hdr is the denoised image too"),
        Param("stereo", "bool", False, doc="render left/right pairs (every key gains a leading axis of 2)"),
        Param("interocular_distance", "float", 0.065, "m", "stereo baseline", check=positive),
        Param("variant", "str", "auto", choices=("auto", "cuda_ad_rgb", "llvm_ad_rgb", "scalar_rgb"),
              doc="Mitsuba variant; auto: cuda, else llvm, else scalar ($HYBRIDGEN_MITSUBA_VARIANT overrides)"),
        *label_params(depth=False, normals=False, map_by=None),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        scene = context.scene
        if cfg["resolution_x"] is not None or cfg["resolution_y"] is not None:
            scene.camera.intrinsics = scene.camera.intrinsics.resized(cfg["resolution_x"], cfg["resolution_y"])
        request = label_request(cfg)
        wants_labels = any((request.depth, request.distance, request.normals, request.map_by, request.albedo,
                            request.flow, request.nocs, request.object_records))
        settings = PathTraceSettings(cfg["samples"], cfg["min_bounces"], cfg["max_bounces"], cfg["glossy_bounces"])
        variant = choose_variant(cfg["variant"])
        context.log(f"color: Mitsuba {variant}, {settings.samples} spp, max_bounces {settings.max_bounces}"
                    + (", denoised" if cfg["denoise"] else ""))
        context.frames_rendered += render_color(
            scene, context.sinks, settings, labels=request if wants_labels else None, seed=context.scene_seed,
            variant=variant, hdr=cfg["output_hdr"], denoise=cfg["denoise"],
            stereo_baseline=cfg["interocular_distance"] if cfg["stereo"] else None,
            default_category_id=context.default_category_id, progress=context.progress,
            indices=context.keypoint_indices())
