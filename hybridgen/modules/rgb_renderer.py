"""``renderer.RgbRenderer``: path-traced color with Mitsuba 3, plus any label passes from the raster view."""
from __future__ import annotations

from typing import Any

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..io.renamed_sink import renamed_sinks
from ..render.passes import color_keys
from ..render.pathtrace.mitsuba_variant import choose_variant
from ..render.pathtrace.path_trace import PathTraceSettings
from ..render.render_color import render_color
from ..render.view_transform import color_encoding
from ..run.context import RunContext
from .base import Module, Role
from .label_params import label_params, label_request, stored_keys


def _non_negative(value: Any) -> str | None:
    return None if value >= 0 else f"must be >= 0, got {value}"


def _optional_non_negative(value: Any) -> str | None:
    return None if value is None else _non_negative(value)


def _optional_positive(value: Any) -> str | None:
    return None if value is None else positive(value)


@register_module("renderer.RgbRenderer")
class RgbRenderer(Module):
    """Renders color for every keypoint; render_depth / render_normals / map_by add labels in the same pass."""

    role = Role.RENDERER
    path_traces = True

    params = (
        Param("samples", "int|null", None, "spp", "null: adaptive sampling up to 768 spp (hybridgen's default), "
              "or up to 1024 (BlenderProc 2.8's) when noise_threshold is given; N: a plain N-spp estimate in every "
              "pixel, or at most N when noise_threshold is given (Cycles' meaning)", check=_optional_positive),
        Param("noise_threshold", "float|null", None, doc="adaptive sampling: a pixel gets no more samples once "
              "its noise estimate (Cycles') is below this (Cycles' meaning: 0.01 is BlenderProc's default); null: "
              "0.005 when samples is null (a sample here costs 0.3-0.45 of Cycles'), else off; 0: off",
              check=_optional_non_negative),
        Param("use_adaptive_sampling", "float|null", None, doc="BlenderProc 1.x's name of noise_threshold",
              check=_optional_non_negative),
        Param("min_samples", "int", 0, "spp", "samples every pixel gets before adaptive sampling judges it "
              "(Cycles' Min Samples); 0: 64 (BlenderProc's) without noise_threshold, else Cycles' automatic value "
              "for it (64 at 0.01, 80 at 0.005)",
              check=_non_negative),
        Param("clamp_indirect", "float", 10.0, doc="firefly control, Cycles' sample_clamp_indirect: indirect "
              "light of one sample is scaled down to at most this linear radiance (direct light never); 0: off",
              check=_non_negative),
        Param("filter_glossy", "float", 1.0, doc="firefly control, Cycles' blur_glossy (1.0, Cycles' default): "
              "glossy lobes are roughened after rough bounces (a highlight seen via a diffuse bounce is blurred); "
              "0: off. JIT variants", check=_non_negative),
        Param("caustics_refractive", "bool", True, doc="Cycles' caustics_refractive (true, Cycles' default): "
              "false drops refraction (glass, spec_trans) at surfaces reached by a diffuse bounce - light through "
              "glass onto diffuse surfaces, a main source of noise in glass scenes; glass seen from the camera or "
              "in mirrors is unchanged. JIT variants"),
        Param("filter_width", "float", 1.5, "px", "pixel filter, Cycles' Blackman-Harris filter_width (1.5, Cycles' "
              "default): samples are spread over +-filter_width px around the pixel centre (importance-sampled); "
              "0: one-pixel box. JIT variants (scalar_rgb: box)", check=_non_negative),
        Param("min_bounces", "int", 1, doc="bounces before Russian roulette may end a path (Cycles' meaning)",
              check=_non_negative),
        Param("max_bounces", "int", 3, doc="indirect bounces, 0 = direct light only (Mitsuba max_depth = "
              "max_bounces + 2); 3 is BlenderProc's default", check=_non_negative),
        Param("diffuse_bounces", "int|null", None, doc="Cycles' per-lobe limit (null: max_bounces); below "
              "max_bounces needs a JIT Mitsuba variant", check=_optional_non_negative),
        Param("glossy_bounces", "int|null", None, doc="Cycles' limit on glossy/specular reflections (null: "
              "max_bounces; BlenderProc's default is 0); below max_bounces needs a JIT Mitsuba variant",
              check=_optional_non_negative),
        Param("transmission_bounces", "int|null", None, doc="Cycles' limit on glossy/specular transmission "
              "(null: max_bounces); below max_bounces needs a JIT Mitsuba variant", check=_optional_non_negative),
        Param("resolution_x", "int|null", None, "px", "overrides the camera width (K scaled)"),
        Param("resolution_y", "int|null", None, "px", "overrides the camera height (K scaled)"),
        Param("view_transform", "str", "Standard", choices=("Standard", "Filmic"),
              doc="how colors (and colors_raw) encode linear light: Standard (the sRGB curve) or Filmic (Blender's "
              "Filmic view, from Blender's own tables where a Blender or bpy is installed, else Standard with a "
              "notice; BlenderProc 1.x configs default to it, as their Blender 2.93 scenes did)"),
        Param("output_hdr", "bool", False, doc="also write linear colors_hdr (float16)"),
        Param("denoise", "bool", True, doc="Open Image Denoise (pyoidn) guided by the raster albedo and normals; "
              "colors_hdr is the denoised image too; false: the raw estimate"),
        Param("output_raw", "bool", False, doc="with denoise: also write colors_raw, the image before denoising "
              "(sRGB uint8 like colors)"),
        Param("output_sample_counts", "bool", False, doc="also write sample_counts (uint32 H x W): the samples each "
              "pixel received"),
        Param("stereo", "bool", False, doc="render left/right pairs (every key gains a leading axis of 2)"),
        Param("interocular_distance", "float", 0.065, "m", "stereo baseline", check=positive),
        Param("variant", "str", "auto", choices=("auto", "cuda_ad_rgb", "llvm_ad_rgb", "scalar_rgb"),
              doc="Mitsuba variant; auto: cuda, else llvm, else scalar ($HYBRIDGEN_MITSUBA_VARIANT overrides)"),
        *label_params(depth=False, normals=False, map_by=None),
    )

    def produces(self) -> frozenset[str] | None:
        cfg = self.config
        return stored_keys(cfg, color_keys(hdr=cfg["output_hdr"], raw=cfg["output_raw"] and cfg["denoise"],
                                           sample_counts=cfg["output_sample_counts"]))

    def run(self, context: RunContext) -> None:
        cfg = self.config
        scene = context.scene
        if cfg["resolution_x"] is not None or cfg["resolution_y"] is not None:
            scene.camera.intrinsics = scene.camera.intrinsics.resized(cfg["resolution_x"], cfg["resolution_y"])
        request = label_request(cfg)
        wants_labels = request.wants_any
        threshold = cfg["noise_threshold"] if cfg["noise_threshold"] is not None else cfg["use_adaptive_sampling"]
        settings = PathTraceSettings(cfg["samples"], cfg["min_bounces"], cfg["max_bounces"], cfg["glossy_bounces"],
                                     noise_threshold=threshold, min_samples=cfg["min_samples"],
                                     clamp_indirect=cfg["clamp_indirect"], diffuse_bounces=cfg["diffuse_bounces"],
                                     transmission_bounces=cfg["transmission_bounces"],
                                     filter_width=cfg["filter_width"], filter_glossy=cfg["filter_glossy"],
                                     caustics_refractive=cfg["caustics_refractive"])
        plan = settings.plan()
        variant = choose_variant(cfg["variant"])
        sampling = (f"adaptive {plan.min_samples}..{plan.max_samples} spp (noise threshold {plan.noise_threshold})"
                    if plan.adaptive else f"{plan.max_samples} spp")
        context.log(f"color: Mitsuba {variant}, {sampling}, max_bounces {settings.max_bounces}"
                    + (f", indirect clamp {settings.clamp_indirect}" if settings.clamp_indirect else "")
                    + (", denoised" if cfg["denoise"] else ""))
        sinks = renamed_sinks(context.sinks, cfg["output_keys"])
        context.frames_rendered += render_color(
            scene, sinks, settings, labels=request if wants_labels else None, seed=context.scene_seed,
            variant=variant, hdr=cfg["output_hdr"], denoise=cfg["denoise"], keep_raw=cfg["output_raw"],
            sample_counts=cfg["output_sample_counts"],
            stereo_baseline=cfg["interocular_distance"] if cfg["stereo"] else None,
            default_category_id=context.default_category_id, progress=context.progress,
            indices=context.keypoint_indices(), encode=color_encoding(cfg["view_transform"]).to_uint8)
