"""What a color render is asked for: samples, adaptive sampling, bounces, clamping and filters (Cycles' and
BlenderProc's knobs and meanings), and the Mitsuba integrator they make."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ...errors import InputError
from .. import pixel_filter
from . import clamped_path, glossy_filter
from .adaptive_sampling import SamplingPlan, automatic_min_samples
from .mitsuba_variant import is_jit

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

    ``edge_min_samples`` (hybridgen's; default 0 = off): with adaptive sampling and denoising, the samples per pixel
    the pixels on edges of the denoising guides get at least (:mod:`hybridgen.render.guide_edges`; at most the
    maximum). BlenderProc scripts render with four times Cycles' automatic minimum (:mod:`hybridgen.bproc.render_frames`).

    ``edge_noise_scale`` (hybridgen's; default 0 = off): with ``edge_min_samples``, the edge pixels get only as many
    samples (at most ``edge_min_samples``) as bring the root mean square of their error estimates to the noise
    threshold divided by this (:meth:`~hybridgen.render.pathtrace.adaptive_sampling.SamplingPlan.edge_samples`).
    BlenderProc scripts render with 4.

    ``edge_raw_weight`` (hybridgen's; default 0 = off): with denoising, the share of the raw (not denoised) value in
    the colors of pixels on strong edges of the denoising guides (:mod:`hybridgen.render.edge_blend`), 0..1.
    BlenderProc scripts render with 0.6, and on every edge pixel with the pooled estimate of
    :mod:`hybridgen.render.pathtrace.pooled_edges`.

    ``flat_noise_scale`` (hybridgen's; default 1): with ``edge_min_samples``, pixels off the guide edges stop at this
    many times the noise threshold (the denoiser smooths them; :mod:`hybridgen.render.pathtrace.adaptive_sampling`).
    BlenderProc scripts render with 1.5.

    ``texture_min_samples`` (hybridgen's; default 0 = off): with adaptive sampling and denoising, the samples per
    pixel the pixels of textured surfaces get at least (:func:`hybridgen.render.guide_edges.textured_pixels`; at most
    the maximum), the texture's own albedo edges included (instead of ``edge_min_samples``). BlenderProc scripts render
    with Cycles' automatic minimum there.

    ``guide_factor`` (hybridgen's; default 3, 1..4): the denoising guides are rasterized at this many times the
    resolution and averaged with the pixel filter (:mod:`hybridgen.render.denoise_guides`). BlenderProc scripts
    render with 2.
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
    edge_min_samples: int = 0
    edge_noise_scale: float = 0.0
    edge_raw_weight: float = 0.0
    flat_noise_scale: float = 1.0
    guide_factor: int = 3  # denoise_guides.DEFAULT_FACTOR
    texture_min_samples: int = 0

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
        if self.texture_min_samples < 0:
            raise InputError(f"texture_min_samples must be >= 0 (0 = off), got {self.texture_min_samples}")
        if self.edge_min_samples < 0:
            raise InputError(f"edge_min_samples must be >= 0 (0 = off), got {self.edge_min_samples}")
        if not (math.isfinite(self.edge_raw_weight) and 0 <= self.edge_raw_weight <= 1):
            raise InputError(f"edge_raw_weight must be in 0..1 (0 = off), got {self.edge_raw_weight}")
        if not 1 <= self.guide_factor <= 4:
            raise InputError(f"guide_factor must be in 1..4, got {self.guide_factor}")
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
        return SamplingPlan(most, min(least, most), threshold, min(self.edge_min_samples, most), self.flat_noise_scale,
                            min(self.texture_min_samples, most), self.edge_noise_scale)

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
