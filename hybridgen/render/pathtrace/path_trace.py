"""The path-trace view: one Mitsuba 3 scene built from the scene model, rendered from any keypoint.

The scene (geometry, BSDFs, lights, integrator) is loaded once; a keypoint only changes the sensor's
``to_world`` through ``mi.traverse``, which rebuilds nothing. The sensor is made from the same K and clip
range as the raster view; color pixel (u, v) is the pixel filter's weighted mean of the radiance around the
centre where the label sample (u, v) is taken (Cycles' Blackman-Harris, :mod:`hybridgen.render.pixel_filter`;
``filter_width: 0``: the one-pixel box ``[u - 0.5, u + 0.5] x [v - 0.5, v + 0.5]``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import InputError
from ...scene.camera import Intrinsics
from ...scene.scene import Scene
from ...scene.depth_of_field import DepthOfField
from . import camera_hidden_emission, clamped_path, glossy_filter, pinhole_sensor, thin_lens_sensor, transparent_shadows
from .. import pixel_filter
from .adaptive_sampling import PixelTracer, SamplingPlan, automatic_min_samples, launch_counts, render_adaptive
from .mitsuba_scene import scene_dict
from .mitsuba_variant import activate, choose_variant, is_jit

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

DEFAULT_MAX_SAMPLES = 768
"""Samples per pixel at most when neither ``samples`` nor ``noise_threshold`` is given (with
:data:`DEFAULT_NOISE_THRESHOLD`): hybridgen's own default, three quarters of BlenderProc's. The pixels that reach
the maximum are the hard ones (object edges and contact regions, glossy and refracting paths), where a sample costs
3-4x an average one, and Open Image Denoise removes most of what their last samples would. Measured on the four
scenes of tools/color_quality.py (320x240, denoised, PSNR against the benchmark's 4096-spp references, CPU s of
``render_color`` with the maxima in turn in one process per scene, AVX2 host; docs/color_quality.md, session 11),
maximum 1024 -> 768 at threshold 0.005: tabletop 54.31 -> 54.10 dB, 9.64 -> 7.66 s; window room 49.09 -> 48.98 dB,
93.1 -> 62.1 s (the maximum binds in most of its pixels); HDRI tabletop 52.80 -> 52.53 dB, 29.9 -> 25.5 s;
materials 51.64 -> 51.12 dB, 32.8 -> 24.3 s. Every scene but materials stays as clean as Cycles at BlenderProc's
defaults (53.2, 48.9, 52.1 dB); 640 and 512 are not (window room 48.90 and 48.77 dB)."""
DEFAULT_MIN_SAMPLES = 64
"""Samples per pixel at least when neither ``samples`` nor ``noise_threshold`` is given (and ``min_samples`` is 0):
BlenderProc's, Cycles' automatic minimum at its threshold 0.01, rather than the 80 Cycles' rule gives for
hybridgen's 0.005. The adaptive rounds then check at 64, 128, 256 and 512 spp (80, 160, 320, 640 before), so
pixels stop nearer the count they need. Measured as :data:`DEFAULT_MAX_SAMPLES` (session 12, 2 seeds): 80 -> 64
gave tabletop 54.10 -> 53.98 dB at 131 -> 116 spp, window room 48.99 -> 48.98 dB at 661 -> 657 spp, HDRI
tabletop 52.49 -> 52.40 dB at 451 -> 365 spp, materials 51.20 -> 51.11 dB at 304 -> 267 spp; the tabletop's
whole process 5.21 -> 4.79 s wall (median of 8 alternating pairs). 48 (checks at 96, 192, 384) gave the HDRI
tabletop 459 spp."""
CYCLES_MAX_SAMPLES = 1024
"""Samples per pixel at most when ``noise_threshold`` is given without ``samples``: BlenderProc 2.8's default
maximum, so a BlenderProc config's threshold stops pixels where its Cycles would."""
DEFAULT_NOISE_THRESHOLD = 0.005
"""Adaptive sampling's threshold when neither ``samples`` nor ``noise_threshold`` is given: half of BlenderProc
2.8's 0.01, because a sample costs about a third of a Cycles sample here (AVX-512; 0.45 with AVX2, where Dr.Jit's
vectors are half as wide: docs/color_quality.md). An explicit ``noise_threshold``
keeps Cycles' meaning (0.01 stops pixels where BlenderProc's Cycles does). Chosen by measurement on the four
scenes of tools/color_quality.py (160x120, denoised, PSNR against 8192-spp references; CPU s of sampling,
guides and denoising in the process, loaded 2-core machine, 2 runs each), thresholds 0.01 / 0.007 / 0.005 /
0.0035: tabletop 51.29 / 52.17 / 52.53 / 52.65 dB at 0.92 / 1.33 / 1.51 / 1.86 s; materials 47.85 / 48.54 /
48.35 / 48.46 dB at 2.58 / 3.43 / 3.78 / 4.42 s; window room 46.48 / 46.77 / 46.93 / 46.89 dB at 5.32 / 6.40 /
6.86 / 7.11 s (the 1024-spp maximum binds); HDRI tabletop 49.11 / 49.87 / 50.22 / 50.36 dB at 1.82 / 2.90 /
3.51 / 4.53 s. 0.005 is the knee: +0.45 to +1.24 dB over 0.01 for 1.3-1.9x the sampling time, while 0.0035
adds at most 0.14 dB more."""


SERIAL_SCENE_LOAD = True
"""Mitsuba loads the scene dictionary on one thread. Its parallel loader (the default) instantiates the scene's
objects on several threads, and the order they finish in decides, e.g., which index the environment emitter gets
- a literal in the traced path kernels (the IR of two runs of the tabletop of tools/color_quality.py differed in
exactly that: 1 or 2). A kernel that differs misses Dr.Jit's kernel cache, so warm runs compiled the path kernels
again (~0.5 s of CPU each): with 16 and 20 processes of that scene in one cache, a second variant appeared after 2
and 7 runs with the parallel loader, none in 20 serial ones (with the aligned mesh buffers of
:func:`hybridgen.render.pathtrace.mitsuba_scene.jit_buffer`). hybridgen hands Mitsuba built meshes and BSDFs, so there is
little left to parallelise; the image bytes are the same either way."""


@dataclass(frozen=True)
class PathTraceSettings:
    """Integrator and sampling settings in BlenderProc's (Cycles') terms.

    Bounces count as in Cycles: ``max_bounces`` 0 is direct light only (default 3, BlenderProc's). Mitsuba's
    ``path`` integrator counts path segments, so ``max_depth = max_bounces + 2`` and Russian roulette starts
    at ``rr_depth = min(min_bounces, max_bounces) + 2``. Per-lobe limits ``diffuse_bounces``,
    ``glossy_bounces``, ``transmission_bounces`` (None: ``max_bounces``; BlenderProc's defaults are 3, 0, 0)
    are honoured by :mod:`hybridgen.render.pathtrace.clamped_path` in the JIT variants; ``scalar_rgb`` (Mitsuba's
    ``path``, one depth limit for all lobes) rejects a value below ``max_bounces`` rather than ignoring it.

    Sampling (see :mod:`hybridgen.render.pathtrace.adaptive_sampling`): with ``samples`` not given, every pixel is
    sampled adaptively from ``min_samples`` (0, the default: :data:`DEFAULT_MIN_SAMPLES`, 64, without
    ``noise_threshold``; Cycles' automatic minimum for a given threshold, 64 at 0.01, 80 at 0.005) until its
    noise estimate is below ``noise_threshold`` (default :data:`DEFAULT_NOISE_THRESHOLD`, 0.005; Cycles'
    meaning when given) or it has :data:`DEFAULT_MAX_SAMPLES` (768; :data:`CYCLES_MAX_SAMPLES`, BlenderProc's
    1024, when ``noise_threshold`` is given).
    An explicit ``samples: N`` is a plain N-spp estimate in every pixel, unless ``noise_threshold`` is given
    too: then N is the maximum (Cycles' meaning of samples with adaptive sampling on). ``noise_threshold`` 0 turns
    adaptive sampling off: every pixel gets ``samples``, or BlenderProc's 1024 when ``samples`` is not given.

    ``clamp_indirect`` (linear radiance; 0 = off) is the firefly control of
    :mod:`hybridgen.render.pathtrace.clamped_path`, Cycles' ``sample_clamp_indirect`` (default 10, Cycles' default):
    indirect contributions are clamped per sample, direct light never. It needs a JIT variant
    (``llvm_ad_rgb``/``cuda_ad_rgb``); ``scalar_rgb`` renders unclamped.

    ``filter_width`` (px): the pixel filter, Cycles' Blackman-Harris of that ``filter_width`` (default 1.5,
    Cycles'), importance-sampled (:mod:`hybridgen.render.pixel_filter`); 0 is the one-pixel box. JIT variants
    only; ``scalar_rgb`` renders through Mitsuba's film with the box filter.

    ``filter_glossy``: Cycles' ``blur_glossy`` (default 1.0, Cycles' and BlenderProc's; 0 = off), glossy lobes
    roughened after rough bounces (:mod:`hybridgen.render.pathtrace.glossy_filter`); JIT variants only.

    ``caustics_refractive``: Cycles' option (default True, Cycles'); False drops refraction at surfaces a diffuse
    bounce led to (:mod:`hybridgen.render.pathtrace.clamped_path`); JIT variants only.
    """

    samples: int | None = None
    min_bounces: int = 1
    max_bounces: int = 3
    glossy_bounces: int | None = None
    noise_threshold: float | None = None
    min_samples: int = 0
    clamp_indirect: float = 10.0
    diffuse_bounces: int | None = None
    transmission_bounces: int | None = None
    filter_width: float = pixel_filter.DEFAULT_WIDTH
    filter_glossy: float = glossy_filter.DEFAULT_FILTER_GLOSSY
    caustics_refractive: bool = True

    def __post_init__(self) -> None:
        if self.samples is not None and self.samples < 1:
            raise InputError(f"samples must be >= 1, got {self.samples}")
        if self.min_bounces < 0 or self.max_bounces < 0:
            raise InputError("min_bounces and max_bounces must be >= 0")
        for name, value in self._lobe_bounces().items():
            if value is not None and value < 0:
                raise InputError(f"{name} must be >= 0, got {value}")
        if self.noise_threshold is not None and not (math.isfinite(self.noise_threshold) and self.noise_threshold >= 0):
            raise InputError(f"noise_threshold must be >= 0 (0 = adaptive sampling off), got {self.noise_threshold}")
        if not (math.isfinite(self.clamp_indirect) and self.clamp_indirect >= 0):
            raise InputError(f"clamp_indirect must be >= 0 (0 = off), got {self.clamp_indirect}")
        if not (math.isfinite(self.filter_glossy) and self.filter_glossy >= 0):
            raise InputError(f"filter_glossy must be >= 0 (0 = off), got {self.filter_glossy}")
        if not (math.isfinite(self.filter_width) and 0 <= self.filter_width <= 10):
            raise InputError(f"filter_width must be in 0..10 px (0 = one-pixel box), got {self.filter_width}")
        self.plan()  # validates the sampling knobs

    def plan(self) -> SamplingPlan:
        """The per-pixel sample plan these settings stand for (rule in the class docstring)."""
        if self.samples is None and self.noise_threshold is None:  # hybridgen's defaults
            threshold, most = DEFAULT_NOISE_THRESHOLD, DEFAULT_MAX_SAMPLES
            least = self.min_samples or DEFAULT_MIN_SAMPLES
        else:  # the given samples, else BlenderProc's maximum; Cycles' automatic minimum for a given threshold
            threshold = self.noise_threshold or 0.0
            most = CYCLES_MAX_SAMPLES if self.samples is None else self.samples
            if threshold == 0:  # adaptivity off: the maximum in every pixel
                return SamplingPlan(most, most, 0.0)
            least = self._min_samples(threshold)
        return SamplingPlan(most, min(least, most), threshold)

    def _min_samples(self, threshold: float) -> int:
        """``min_samples``, or Cycles' automatic minimum for ``threshold`` (> 0) when it is 0."""
        return self.min_samples if self.min_samples != 0 else automatic_min_samples(threshold)

    def integrator(self) -> dict[str, Any]:
        """Mitsuba's built-in ``path`` integrator with these bounces (no clamping)."""
        rr_depth = min(self.min_bounces, self.max_bounces) + 2  # no roulette needed past the last bounce
        return {"type": "path", "max_depth": self.max_bounces + 2, "rr_depth": rr_depth,
                "hide_emitters": False}

    def _lobe_bounces(self) -> dict[str, int | None]:
        return {"diffuse_bounces": self.diffuse_bounces, "glossy_bounces": self.glossy_bounces,
                "transmission_bounces": self.transmission_bounces}

    def lobe_limits(self) -> dict[str, int]:
        """The per-lobe limits below ``max_bounces`` (the others are implied by it)."""
        return {name: value for name, value in self._lobe_bounces().items()
                if value is not None and value < self.max_bounces}

    def integrator_for(self, variant: str, transparent_shadows: bool = False) -> dict[str, Any]:
        """The integrator used in ``variant``: hybridgen's clamped path tracer wherever it can run (JIT variants;
        also with clamp and filter glossy off, so every JIT render draws the unbiased samples of
        :mod:`hybridgen.render.pathtrace.owen_sobol`; it handles per-lobe limits, ``transparent_shadows`` for a scene with
        alpha surfaces: :mod:`hybridgen.render.pathtrace.transparent_shadows`, and emitters hidden from the camera:
        :mod:`hybridgen.render.pathtrace.camera_hidden_emission`), else :meth:`integrator` (``volpath`` in ``scalar_rgb``
        with ``transparent_shadows``)."""
        limits = self.lobe_limits()
        if not is_jit(variant):
            if limits:
                raise InputError(f"{', '.join(f'{k} ({v})' for k, v in limits.items())} < max_bounces "
                                 f"({self.max_bounces}) needs a JIT Mitsuba variant (llvm_ad_rgb or cuda_ad_rgb): "
                                 f"{variant}'s path tracer has one depth limit for every lobe")
            return {**self.integrator(), "type": "volpath"} if transparent_shadows else self.integrator()
        clamped_path.register(variant)
        plain = self.integrator()
        keys = {"diffuse_bounces": "max_diffuse", "glossy_bounces": "max_glossy",
                "transmission_bounces": "max_transmission"}
        return {"type": clamped_path.PLUGIN_NAME, "max_depth": plain["max_depth"], "rr_depth": plain["rr_depth"],
                "clamp_indirect": float(self.clamp_indirect), "filter_glossy": float(self.filter_glossy),
                "caustics_refractive": bool(self.caustics_refractive),
                **{keys[k]: v for k, v in limits.items()},
                **({"transparent_shadows": True} if transparent_shadows else {})}


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

    def render(self, cam2world: np.ndarray, seed: int, spp: int | None = None) -> np.ndarray:
        """Linear RGB of one keypoint; ``seed`` fixes the sample pattern (same seed -> same bytes). ``spp``
        forces a plain fixed-count estimate."""
        return self.render_with_counts(cam2world, seed, spp)[0]

    def render_with_counts(self, cam2world: np.ndarray, seed: int,
                           spp: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Linear RGB (float32 H x W x 3) and samples per pixel (uint32 H x W) of one keypoint, sampled by
        the settings' plan (adaptive or fixed; ``spp`` forces a fixed count)."""
        import mitsuba as mi

        self.set_pose(cam2world)
        plan = SamplingPlan(spp, spp, 0.0) if spp else self.settings.plan()
        if self._own_film:
            image = mi.render(self.mi_scene, sensor=self.sensor, spp=plan.max_samples, seed=int(seed))
            counts = np.full((self.intrinsics.height, self.intrinsics.width), plan.max_samples, np.uint32)
            return np.array(image, dtype=np.float32)[..., :3], counts
        return render_adaptive(self._tracer, plan, int(seed))


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
