"""The path-trace view: one Mitsuba 3 scene built from the scene model, rendered from any keypoint.

The scene (geometry, BSDFs, lights, integrator) is loaded once; a keypoint only changes the sensor's
``to_world`` through ``mi.traverse``, which rebuilds nothing. The sensor is made from the same K and clip
range as the raster view; color pixel (u, v) is the pixel filter's weighted mean of the radiance around the
centre where the label sample (u, v) is taken (Cycles' Blackman-Harris, :mod:`hybridgen.render.pixel_filter`;
``filter_width: 0``: the one-pixel box ``[u - 0.5, u + 0.5] x [v - 0.5, v + 0.5]``).
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ...errors import InputError
from ...scene.camera import Intrinsics
from ...scene.depth_of_field import DepthOfField
from ...scene.scene import Scene
from . import (camera_hidden_emission, clamped_path, layered_emission, pinhole_sensor, thin_lens_sensor,
               transparent_shadows)
from .adaptive_sampling import SamplingPlan, render_adaptive
from .mitsuba_scene import scene_dict
from .mitsuba_variant import activate, choose_variant, is_jit
from .path_trace_settings import (CYCLES_MAX_SAMPLES, DEFAULT_MAX_SAMPLES, DEFAULT_MIN_SAMPLES, DEFAULT_NOISE_THRESHOLD,
                                  PathTraceSettings)
from .pixel_tracer import PixelTracer, launch_counts
from .pooled_edges import PooledEdges

__all__ = ["CYCLES_MAX_SAMPLES", "DEFAULT_MAX_SAMPLES", "DEFAULT_MIN_SAMPLES", "DEFAULT_NOISE_THRESHOLD",
           "FullFrameTracer", "PathTraceSettings", "PathTraceView", "SAMPLER", "mitsuba_pixel_centre_depth",
           "sensor_dict"]

OPENCV_TO_MITSUBA = np.diag([-1.0, -1.0, 1.0, 1.0])
"""Mitsuba's camera looks along +z with +y up and +x to the image's left; OpenCV's x is right, y down."""


SAMPLER = "ldsampler"
"""The sensor's Mitsuba sampler. hybridgen's Python integrator (every default render in a JIT variant) draws
from :mod:`hybridgen.render.pathtrace.owen_sobol` in its place (unbiased: this sampler's dimensions correlate, see
:data:`hybridgen.render.pathtrace.adaptive_sampling.OWEN_SOBOL`); Mitsuba's own integrators (``scalar_rgb``, or clamp and
filter glossy both off) use it. It is Mitsuba's low-discrepancy sampler (a scrambled (0, 2)-sequence per pair of
dimensions, the sample order shuffled per dimension), stratified like Cycles' Sobol pattern. Because of the
shuffle, the two halves adaptive sampling compares are random halves of a stratified set, so its error
estimate is conservative (it sees more noise than the full estimate has) and pixels may get more samples
than the threshold strictly needs. Against Mitsuba's default ``independent`` random numbers it lowers the
noise of the tabletop scene of tools/color_quality.py at 16 / 64 / 256 spp from 28.5 / 34.3 / 40.1 dB to
35.3 / 40.7 / 45.5 dB (PSNR against a 4096-spp reference): as clean as 8-16x the samples, for ~15 % more
CPU time per sample. Sample counts are traced as whole 4^k-point patterns
(:func:`hybridgen.render.pathtrace.adaptive_sampling.launch_counts`)."""



SERIAL_SCENE_LOAD = True
"""Mitsuba loads the scene dictionary on one thread. Its parallel loader (the default) instantiates the scene's
objects on several threads, and the order they finish in decides, e.g., which index the environment emitter gets
- a literal in the traced path kernels (the IR of two runs of the tabletop of tools/color_quality.py differed in
exactly that: 1 or 2). A kernel that differs misses Dr.Jit's kernel cache, so warm runs compiled the path kernels
again (~0.5 s of CPU each): with 16 and 20 processes of that scene in one cache, a second variant appeared after 2
and 7 runs with the parallel loader, none in 20 serial ones (with the aligned mesh buffers of
:func:`hybridgen.render.pathtrace.mitsuba_scene.jit_buffer`). hybridgen hands Mitsuba built meshes and BSDFs, so there is
little left to parallelise; the image bytes are the same either way."""


def sensor_dict(intr: Intrinsics, cam2world: np.ndarray, variant: str,
                depth_of_field: DepthOfField | None = None) -> dict[str, Any]:
    """The sensor of ``intr`` with a one-pixel box filter.

    JIT variants use :mod:`hybridgen.render.pathtrace.pinhole_sensor` (any K), or with a ``depth_of_field``
    :mod:`hybridgen.render.pathtrace.thin_lens_sensor`; ``scalar_rgb``, where a Python sensor would run per sample, uses
    Mitsuba's ``perspective`` sensor, which needs square pixels (and has no depth of field).
    """
    import mitsuba as mi

    film = {"type": "hdrfilm", "width": intr.width, "height": intr.height, "pixel_format": "rgb",
            "rfilter": {"type": "box"}, "sample_border": False}
    fx, fy, cx, cy = intr.K[0, 0], intr.K[1, 1], intr.K[0, 2], intr.K[1, 2]
    common = {"near_clip": intr.clip_start, "far_clip": intr.clip_end, "film": film,
              "sampler": {"type": SAMPLER}}
    if is_jit(variant) and depth_of_field is not None:
        return thin_lens_sensor.sensor(intr, cam2world, variant, depth_of_field, common)
    if depth_of_field is not None:
        raise InputError("depth of field needs a JIT Mitsuba variant (llvm_ad_rgb or cuda_ad_rgb; install "
                         "libllvm19)")
    if is_jit(variant):
        pinhole_sensor.register(variant)
        return {"type": pinhole_sensor.PLUGIN_NAME, "fx": fx, "fy": fy, "cx": cx, "cy": cy, **common}
    if not math.isclose(fx, fy, rel_tol=1e-9):
        raise InputError(f"fx != fy ({fx} vs {fy}) needs a JIT Mitsuba variant (llvm_ad_rgb or cuda_ad_rgb); "
                         "scalar_rgb's perspective sensor has square pixels (install libllvm19)")
    return {
        "type": "perspective",
        "fov_axis": "x",
        "fov": math.degrees(2 * math.atan(intr.width / (2 * fx))),
        # Mitsuba measures the principal point offset in film widths/heights, positive towards -u / -v.
        "principal_point_offset_x": -(cx - (intr.width - 1) / 2) / intr.width,
        "principal_point_offset_y": -(cy - (intr.height - 1) / 2) / intr.height,
        "to_world": mi.ScalarTransform4f((np.asarray(cam2world) @ OPENCV_TO_MITSUBA).tolist()),
        **common,
    }


class PathTraceView:
    """Renders linear RGB (float32, H x W x 3, top-down) of ``scene`` for any keypoint of its camera."""

    def __init__(self, scene: Scene, settings: PathTraceSettings | None = None, *, variant: str | None = None,
                 integrator: dict[str, Any] | None = None) -> None:
        import mitsuba as mi

        self.settings = settings or PathTraceSettings()
        self.variant = choose_variant(variant)
        activate(self.variant)
        self.intrinsics = scene.camera.intrinsics
        description = scene_dict(scene)
        self._own_film = integrator is not None  # e.g. AOV integrators: rendered through Mitsuba's film
        hidden = [] if integrator is not None else camera_hidden_emission.hidden_emitter_keys(scene)
        description["integrator"] = integrator or self.settings.integrator_for(
            self.variant, transparent_shadows=transparent_shadows.scene_has_masks(scene))
        first = scene.camera.keypoints[0] if scene.camera.keypoints else np.eye(4)
        description["sensor"] = sensor_dict(self.intrinsics, first, self.variant, scene.camera.depth_of_field)
        try:  # serially: see SERIAL_SCENE_LOAD
            self.mi_scene = mi.load_dict(description, parallel=not SERIAL_SCENE_LOAD)
        except RuntimeError as exc:
            raise InputError(f"Mitsuba could not build the scene: {str(exc).splitlines()[-1]}") from None
        self.sensor = self.mi_scene.sensors()[0]
        self._sensor_params = None if is_jit(self.variant) else mi.traverse(self.sensor)
        self.own_integrator = description["integrator"]["type"] == clamped_path.PLUGIN_NAME
        self.clamped = self.own_integrator and self.settings.clamp_indirect > 0
        self._tracer: PixelTracer | FullFrameTracer = (
            PixelTracer(self.mi_scene, self.sensor, self.mi_scene.integrator(), self.settings.filter_width)
            if is_jit(self.variant) else FullFrameTracer(self))
        if self.own_integrator:
            integrator = self.mi_scene.integrator()
            # the per-lane singular-surface test only where a material can be singular
            integrator.singular_surfaces = any(clamped_path.may_be_singular(obj.material) for obj in scene.objects)
            if hidden:
                integrator.hidden_shapes = camera_hidden_emission.hidden_shapes(description, hidden)
            integrator.layered_emitters = layered_emission.emitters(scene, description)
        elif hidden:
            from ...config.notices import notice

            notice(f"{len(hidden) // 2} emitter(s) hidden from the camera (emission_hidden_from_camera, e.g. 3D-FRONT "
                   f"ceilings and lamps) glow for the camera too in {self.variant} (needs a JIT variant)")

    def set_pose(self, cam2world: np.ndarray) -> None:
        """Move the sensor to an OpenCV-axes ``cam2world`` (nothing else is rebuilt)."""
        import mitsuba as mi

        if self._sensor_params is None:  # the pinhole sensor holds its pose as an opaque variable
            self.sensor.set_pose(cam2world)
            return
        self._sensor_params["to_world"] = mi.ScalarTransform4f((np.asarray(cam2world) @ OPENCV_TO_MITSUBA).tolist())
        self._sensor_params.update()

    @property
    def filter_width(self) -> float:
        """The pixel filter's width (px) this view renders with (0: one-pixel box)."""
        return self.settings.filter_width if isinstance(self._tracer, PixelTracer) and not self._own_film else 0.0

    def pooled_edges(self) -> PooledEdges | None:
        """A pool for :meth:`render_with_counts` when this view's tracer can pool edge pixels (JIT variants with
        hybridgen's Owen-Sobol sampler and a pixel filter wider than the pixel), else None."""
        tracer = self._tracer
        if not isinstance(tracer, PixelTracer) or not tracer.owen_sobol or self._own_film or self.filter_width <= 0:
            return None
        return PooledEdges(tracer.width, tracer.height, self.filter_width)

    def render(self, cam2world: np.ndarray, seed: int, spp: int | None = None) -> np.ndarray:
        """Linear RGB of one keypoint; ``seed`` fixes the sample pattern (same seed -> same bytes). ``spp``
        forces a plain fixed-count estimate."""
        return self.render_with_counts(cam2world, seed, spp)[0]

    def render_with_counts(self, cam2world: np.ndarray, seed: int, spp: int | None = None,
                           edges: Callable[[], np.ndarray | None] | None = None,
                           pool: PooledEdges | None = None,
                           textured: Callable[[], np.ndarray | None] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Linear RGB (float32 H x W x 3) and samples per pixel (uint32 H x W) of one keypoint, sampled by
        the settings' plan (adaptive or fixed; ``spp`` forces a fixed count); ``edges``: the pixels the plan's
        ``edge_min_samples`` applies to, ``pool`` their pooled estimate, ``textured`` the pixels its
        ``texture_min_samples`` applies to (:func:`~hybridgen.render.pathtrace.adaptive_sampling.render_adaptive`)."""
        import mitsuba as mi

        self.set_pose(cam2world)
        plan = SamplingPlan(spp, spp, 0.0) if spp else self.settings.plan()
        if self._own_film:
            image = mi.render(self.mi_scene, sensor=self.sensor, spp=plan.max_samples, seed=int(seed))
            counts = np.full((self.intrinsics.height, self.intrinsics.width), plan.max_samples, np.uint32)
            return np.array(image, dtype=np.float32)[..., :3], counts
        return render_adaptive(self._tracer, plan, int(seed), edges, pool, textured)


class FullFrameTracer:
    """The :class:`~hybridgen.render.pathtrace.adaptive_sampling.PixelTracer` interface for ``scalar_rgb``, where a
    per-sample Python loop would be slow: each call renders the whole frame through Mitsuba's film and returns
    the pixels asked for, so adaptive sampling there decides counts but saves no time.

    Each half of the samples is rendered as counts the sensor's sampler takes whole (Mitsuba's low-discrepancy
    sampler rounds a count up to a power of 4: :func:`~hybridgen.render.pathtrace.adaptive_sampling.launch_counts`), so the
    samples traced are the samples counted."""

    owen_sobol = False
    """Mitsuba's film draws from the sensor's own sampler here (rounds are independent patterns)."""
    whole_frames = True
    """Every call renders every pixel: :func:`~hybridgen.render.pathtrace.adaptive_sampling.render_adaptive` calls it once
    per round, however many pixels are active."""

    def __init__(self, view: PathTraceView) -> None:
        self.view = view
        self.width, self.height = view.intrinsics.width, view.intrinsics.height

    def trace(self, pixels: np.ndarray, spp: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        import mitsuba as mi

        sampler = self.view.sensor.sampler().class_name()
        sums = []
        for half, count in enumerate((spp // 2, spp - spp // 2) if spp % 2 == 0 else (spp,)):
            total = np.zeros((len(pixels), 3))
            for launch, size in enumerate(launch_counts(count, sampler)):
                image = mi.render(self.view.mi_scene, sensor=self.view.sensor, spp=size,
                                  seed=(int(seed) + (2 * launch + half) * 0x9E3779B9) % 2**32)
                total += np.array(image, dtype=np.float64)[..., :3].reshape(-1, 3)[pixels] * size
            sums.append(total)
        return sums[0], (sums[1] if len(sums) > 1 else np.zeros_like(sums[0]))


def mitsuba_pixel_centre_depth(view: PathTraceView, cam2world: np.ndarray) -> np.ndarray:
    """Camera-z depth (m, float64, ``inf`` for misses) of the first surface Mitsuba's own sensor and ray
    tracer find through every pixel centre - an independent check of the raster labels' alignment."""
    import drjit as dr
    import mitsuba as mi

    view.set_pose(cam2world)
    intr = view.intrinsics
    u, v = np.meshgrid(np.arange(intr.width) + 0.5, np.arange(intr.height) + 0.5)
    film_pos = np.stack([u.ravel() / intr.width, v.ravel() / intr.height], axis=1)
    origin, forward = np.asarray(cam2world)[:3, 3], np.asarray(cam2world)[:3, 2]
    if dr.is_jit_v(mi.Float):
        ray, _ = view.sensor.sample_ray(0.0, 0.5, mi.Point2f(film_pos[:, 0], film_pos[:, 1]), mi.Point2f(0.5, 0.5))
        si = view.mi_scene.ray_intersect(ray)
        points = np.stack([np.array(c, dtype=np.float64) for c in (si.p.x, si.p.y, si.p.z)], axis=1)
        valid = np.array(si.is_valid(), dtype=bool)
    else:
        points = np.zeros((len(film_pos), 3))
        valid = np.zeros(len(film_pos), dtype=bool)
        for i, (x, y) in enumerate(film_pos):
            ray, _ = view.sensor.sample_ray(0.0, 0.5, mi.Point2f(x, y), mi.Point2f(0.5, 0.5))
            si = view.mi_scene.ray_intersect(ray)
            valid[i] = bool(si.is_valid())
            points[i] = [si.p.x, si.p.y, si.p.z]
    depth = np.where(valid, (points - origin) @ forward, np.inf)
    return depth.reshape(intr.height, intr.width)
