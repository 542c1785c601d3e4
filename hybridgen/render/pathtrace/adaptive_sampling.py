"""Adaptive sampling: more samples where the image is still noisy, up to a maximum (Cycles' scheme).

Knobs (Cycles' and BlenderProc's names and meaning):

- ``noise_threshold``: a pixel stops receiving samples once its error estimate is below five times it
  (Cycles' "Noise Threshold" with Cycles' factor of 5, verified below; BlenderProc's ``set_noise_threshold``
  / 1.x ``use_adaptive_sampling``; 0.01 is BlenderProc's default, hybridgen's is 0.005:
  :data:`hybridgen.render.pathtrace.path_trace.DEFAULT_NOISE_THRESHOLD`; smaller is cleaner and slower). 0 disables
  adaptivity: every pixel gets ``max_samples``.
- ``max_samples``: samples per pixel a pixel never exceeds (Cycles' ``samples`` when adaptive).
- ``min_samples``: samples every pixel gets before the first error estimate (Cycles' "Min Samples"); 0, the
  default, means Cycles' automatic value (:func:`automatic_min_samples`: 64 at threshold 0.01).

The error estimate is Cycles' (after Dammertz et al. 2010, "A hierarchical automatic stopping condition
for Monte Carlo global illumination"; ``film_adaptive_sampling_convergence_check`` in Cycles'
``kernel/film/adaptive_sampling.h``): every pixel's samples are split into two independent halves A and B
of equal count; with ``I = (A + B) / 2`` the pixel mean and ``A`` the first half's mean (linear RGB),

    error = (|I_r - A_r| + |I_g - A_g| + |I_b - A_b|) / (1e-4 + n(I_r + I_g + I_b)),
    n(s) = sqrt(s) for s < 1, s from 1 on,

a relative error that tolerates more absolute noise in bright pixels, as the eye (and a tone curve) does.
(Cycles keeps sums, not means: its auxiliary pass accumulates every other sample times two, and both
differences and intensity are multiplied by 1/samples - the same quantity. ``n`` switched from sqrt
everywhere to ``s`` above 1 in Cycles 3.5, "Improve adaptive sampling for overexposed scenes"; BlenderProc
2.8 runs Blender 4.2.) Cycles compares it with five times the ``noise_threshold`` it is given:
``Integrator::get_adaptive_sampling`` in Cycles' ``scene/integrator.cpp`` multiplies the threshold by 5
("arbitrary factor that makes the threshold more similar to what it was before") before the kernel sees it,
and so does hybridgen (:data:`CYCLES_THRESHOLD_SCALE`): a BlenderProc config's ``noise_threshold: 0.01``
stops pixels where Cycles would.

Measured (``tools/cycles_render.py``'s ``sample_counts``, Cycles' "Debug Sample Count" pass, pip bpy 5.0.1,
BlenderProc 2.8's defaults: threshold 0.01, at most 1024 spp; tools/color_quality.py's tabletop at 160x120):
Cycles spends 110 spp per pixel on average (90 % of the pixels stop at its minimum, 80; 0.7 % reach 1024).
hybridgen with factor 5: 66 spp on average (83 with sqrt everywhere), the map of counts correlating with
Cycles' at r = 0.82 in log (0.72 with sqrt); with factor 1: 381 spp, 28 % of the pixels at 1024, r = 0.34 -
factor 1 is not Cycles' meaning. The remaining difference is the minimum, not the factor: Cycles'
``adaptive_min_samples`` 0 (BlenderProc leaves it so) means ``ceil(16 / threshold^0.3)`` = 64 at 0.01, and
its first check comes after ``(min + 1) | 15`` + 1 = 80 samples, then every 16 (hybridgen doubles per
round). hybridgen's minimum was 16; with Cycles' automatic minimum (now the default, ``min_samples: 0``) it
spends 105 spp (89.5 % of the pixels at 64, r = 0.87), +0.6 dB against its 2048-spp reference after denoising
(49.6 -> 50.2 dB) at the same CPU time within noise (0.88 -> 0.92 s for the whole frame: fixed costs dominate
at this size); on the window room (Cycles 614 spp mean, hybridgen 705) 44.2 -> 44.3 dB.

A pixel is still active when its error, or that of one of its 8 neighbours, is at least that
(the neighbourhood keeps isolated noisy pixels from stopping next to noisy regions). Rounds double the
sample count of the active pixels (``min_samples``, then +``min_samples``, +2x, ... up to ``max_samples``),
so a pixel's count is ``min_samples * 2^k`` or ``max_samples``; converged pixels stay converged.

Cycles checks every 16 samples instead, so a pixel here may get up to twice the samples it would stop at
there. Checking as finely (every 16 samples from 64, every 64 from 256: at most a quarter over) was measured
and is not better: fewer samples, but less clean per CPU second - each check is another chance for the noisy
error estimate of a pixel that is not converged to dip below the threshold, and each is a kernel launch
(~10 ms of tracing Python). tools/color_quality.py's tabletop and HDRI tabletop at 160x120, denoised, PSNR
against 2048-spp references, path-trace CPU s on the loaded 2-core machine, 3 runs each (threshold 0.01 / 0.005):
doubling 50.19 dB 0.84 s / 51.49 dB 1.41 s and 48.03 dB 1.56 s / 49.24 dB 3.50 s; every 16 then 64
49.91 dB 1.26 s / 51.06 dB 1.65 s and 47.14 dB 1.75 s / 48.90 dB 3.26 s.

Only active pixels are traced: :class:`PixelTracer` launches one wavefront of ``len(pixels) x spp``
samples through the loaded scene's integrator and sensor (pixel-major, so each pixel's samples are
contiguous and summed in NumPy in a fixed order - the result does not depend on thread scheduling).
Sample counts, pixel indices and seeds are opaque Dr.Jit variables, so later rounds and keypoints reuse
the kernels compiled by the first (``tools/bench_color.py`` counts compilations per keypoint). Each round
and chunk has its own seed derived from the keypoint's, so the result is a pure function of the seed.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import InputError
from .. import pixel_filter
from .owen_sobol import OwenSobol, mix

CYCLES_THRESHOLD_SCALE = 5.0
"""The error estimate is compared with ``noise_threshold`` times this (Cycles' own factor, in its
``Integrator::get_adaptive_sampling``; see the module docstring for the measurement)."""
LAUNCH_STREAM = 1 << 20
"""Round index (never reached by adaptive rounds) whose seeds the second and later launches of one trace use."""
MAX_WAVEFRONT = 1 << 23
"""Samples per kernel launch at most (bounds the per-sample output arrays to ~100 MB). 2^23 rather than 2^22: the
default first round at 320x240 (64 spp, 4.9 M samples) is one launch instead of two. Tabletop of
tools/color_quality.py, whole warm processes, alternating pairs, the same bytes: medians 5.17 -> 4.95 s wall over 8
pairs, 4.83 -> 4.78 s over 10 (session 12; session 11 found 4 M and 8 M within noise with the 80-spp rounds)."""
MAX_PATTERN = 1024
"""Most samples one low-discrepancy pattern gives a pixel (4^5 points); more are traced as several patterns."""


@dataclass(frozen=True)
class SamplingPlan:
    """How many samples each pixel gets; ``noise_threshold`` 0 means exactly ``max_samples`` everywhere."""

    max_samples: int = 1024
    min_samples: int = 16
    noise_threshold: float = 0.01

    def __post_init__(self) -> None:
        if self.max_samples < 1:
            raise InputError(f"samples must be >= 1, got {self.max_samples}")
        if self.noise_threshold < 0:
            raise InputError(f"noise_threshold must be >= 0, got {self.noise_threshold}")
        if self.adaptive and self.max_samples < 2:
            raise InputError(f"adaptive sampling (noise_threshold {self.noise_threshold}) compares two halves of a "
                             f"pixel's samples: samples must be >= 2, got {self.max_samples}")
        if self.adaptive and not 2 <= self.min_samples <= self.max_samples:
            raise InputError(f"min_samples must be in 2..samples ({self.max_samples}), got {self.min_samples}")

    @property
    def adaptive(self) -> bool:
        return self.noise_threshold > 0

    def rounds(self) -> list[int]:
        """Samples added to every still-active pixel in each round. Adaptive rounds add even counts (the two
        halves stay equal), so an odd ``max_samples`` is rounded down by one there."""
        if not self.adaptive:
            return [self.max_samples]
        first = self.min_samples - self.min_samples % 2
        out, total = [first], first
        while True:
            step = min(total, self.max_samples - total)
            step -= step % 2
            if step == 0:
                return out
            out.append(step)
            total += step


def automatic_min_samples(noise_threshold: float) -> int:
    """Cycles' minimum samples when its ``adaptive_min_samples`` is 0 (BlenderProc leaves it so):
    ``max(4, ceil(16 / noise_threshold^0.3))`` - 32 at 0.1, 64 at 0.01, 128 at 0.001 - rounded up to an even
    count (the two halves stay equal); ``noise_threshold`` as given by the user (before the factor 5)."""
    count = max(4, math.ceil(16.0 / noise_threshold ** 0.3))
    return count + count % 2


def pixel_error(sum_a: np.ndarray, sum_b: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Cycles' per-pixel error estimate (see the module docstring) from the two halves' sample sums
    (N x 3 each) and the samples per pixel ``count`` (N,), half of them in each sum."""
    half = np.maximum(count, 2)[:, None] / 2.0
    mean_a, mean = sum_a / half, (sum_a + sum_b) / (2.0 * half)
    difference = np.abs(mean - mean_a).sum(axis=1)
    intensity = np.maximum(mean.sum(axis=1), 0.0)
    return difference / (1e-4 + np.where(intensity < 1.0, np.sqrt(intensity), intensity))


def dilate(mask: np.ndarray) -> np.ndarray:
    """``mask`` (H x W bool) grown by one pixel in all 8 directions."""
    padded = np.pad(mask, 1)
    h, w = mask.shape
    out = np.zeros_like(mask)
    for dy in range(3):
        for dx in range(3):
            out |= padded[dy:dy + h, dx:dx + w]
    return out


def round_seed(seed: int, round_index: int, chunk: int) -> int:
    """Sampler seed of one launch: a pure function of the keypoint seed, the round and the chunk."""
    return int(np.random.SeedSequence([int(seed), round_index, chunk]).generate_state(1)[0])


class PixelTracer:
    """Traces chosen pixels of the loaded Mitsuba scene (JIT variants only)."""

    whole_frames = False
    """Traces only the pixels asked for, so :func:`render_adaptive` splits large rounds into launches of at most
    :data:`MAX_WAVEFRONT` samples."""

    def __init__(self, mi_scene: Any, sensor: Any, integrator: Any,
                 filter_width: float = pixel_filter.DEFAULT_WIDTH) -> None:
        import mitsuba as mi

        self.mi_scene, self.sensor, self.integrator = mi_scene, sensor, integrator
        size = sensor.film().crop_size()
        self.width, self.height = int(size[0]), int(size[1])
        table = pixel_filter.inverse_cdf_table(filter_width)
        # offsets from the pixel's corner (the centre is at +0.5), as the sample warp's lookup table
        self._filter_table = mi.Float((table + 0.5).astype(np.float32))
        self._python_integrator = isinstance(integrator, mi.SamplingIntegrator) and \
            type(integrator).__module__ != mi.SamplingIntegrator.__module__  # a plugin written in Python
        self._world_radiance: Any = None  # hybridgen/render/pathtrace/world_guide.py, found on the first guide_world()
        self.world_guide: Any = None  # the guide of the last guide_world() (None: the world is not light-sampled)
        # hybridgen's own sampler in place of Mitsuba's low-discrepancy one where the integrator takes any sampler
        # object (render/pathtrace/owen_sobol.py); another sensor sampler (e.g. tests' "independent") is kept
        self.owen_sobol = OWEN_SOBOL and self._python_integrator and \
            sensor.sampler().class_name() == "LowDiscrepancySampler"

    def guide_world(self) -> None:
        """Learns, for the sensor's current pose, where an enclosed constant world is seen from
        (:mod:`hybridgen.render.pathtrace.world_guide`, off unless ``world_guide.ENABLED``) and hands it to the
        integrator; nothing for integrators without the hook (Mitsuba's own) or scenes whose world is
        light-sampled already or open."""
        from . import world_guide

        if not hasattr(self.integrator, "world_guide"):
            return
        if not world_guide.ENABLED:
            self.world_guide = self.integrator.world_guide = None
            return
        if self._world_radiance is None:
            self._world_radiance = world_guide.constant_world_radiance(self.mi_scene) or False
        guide = world_guide.learn(self.mi_scene, self.sensor) if self._world_radiance else None
        if guide is not None and guide.open_fraction >= world_guide.MAX_OPEN_FRACTION:
            guide = None
        self.world_guide = guide
        self.integrator.world_guide = None if guide is None else world_guide.JitGuide.of(guide, self._world_radiance)

    def trace(self, pixels: np.ndarray, spp: int, seed: int,
              first: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Sums of linear RGB over the first and the second half of ``spp`` samples of every pixel in
        ``pixels`` (flat indices ``v * width + u``): two float64 arrays of shape (len(pixels), 3).

        hybridgen's Owen-Sobol sampler (:data:`OWEN_SOBOL`) gives each pixel one pattern per ``seed`` (the
        keypoint's: adaptive rounds continue it) and traces its samples number ``first`` (per pixel, 0 if not
        given) to ``first + spp - 1``: a pixel's samples of all rounds are one prefix of its sequence, every
        power-of-two part of it stratified. The sensor's Mitsuba sampler may only accept some sample counts
        (stratified patterns: powers of two for ``ldsampler``), so ``spp`` is split into counts it accepts
        (:func:`launch_counts`); equal counts are one launch (a pattern per count and pixel), each launch with its
        own seed derived from ``seed``; each pattern's first half of samples goes to the first sum.
        An odd ``spp`` (fixed-count rendering only) leaves the odd sample in the first sum."""
        if self.owen_sobol:
            return self._launch(pixels, spp, 1, seed, np.zeros(len(pixels), np.uint32) if first is None else first)
        sum_a, sum_b = np.zeros((len(pixels), 3)), np.zeros((len(pixels), 3))
        counts = launch_counts(spp, self.sensor.sampler().class_name())
        launches = [(count, len(list(same))) for count, same in itertools.groupby(counts)]
        for index, (count, copies) in enumerate(launches):
            a, b = self._launch(pixels, count, copies,
                                seed if index == 0 else round_seed(seed, LAUNCH_STREAM, index))
            sum_a += a
            sum_b += b
        return sum_a, sum_b

    def _launch(self, pixels: np.ndarray, spp: int, copies: int, seed: int,
                first: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """One wavefront of ``len(pixels) x copies x spp`` samples, pixel-major: ``copies`` patterns of ``spp``
        samples per pixel (each copy of a pixel is its own sequence for the sampler: its own scramble); the
        halves' sums as :meth:`trace`, each half the sum of the copies' halves. With the Owen-Sobol sampler
        (one copy) the samples are numbers ``first`` .. ``first + spp - 1`` of each pixel's pattern."""
        import drjit as dr
        import mitsuba as mi

        n = len(pixels) * copies
        pixels = np.repeat(pixels, copies)
        spp_o, width_o = dr.opaque(mi.UInt32, spp), dr.opaque(mi.UInt32, self.width)
        index = dr.arange(mi.UInt32, n * spp)
        local = index // spp_o
        pixel = dr.gather(mi.UInt32, mi.UInt32(np.ascontiguousarray(pixels, np.uint32)), local)
        v = pixel // width_o
        u = pixel - v * width_o
        if self.owen_sobol:  # each pixel one pattern, seeded by the keypoint and the pixel
            start = dr.gather(mi.UInt32, mi.UInt32(np.ascontiguousarray(first, np.uint32)), local)
            sampler = OwenSobol(start + index - local * spp_o, mix(pixel ^ dr.opaque(mi.UInt32, mix(seed % 2**32))))
        else:
            sampler = self.sensor.sampler().fork()
            sampler.set_sample_count(pattern_size(spp, sampler.class_name()))
            sampler.set_samples_per_wavefront(spp)
            sampler.seed(dr.opaque(mi.UInt32, seed % 2**32), n * spp)
        offset = self._filter_offset(sampler.next_2d())
        position = mi.Point2f((mi.Float(u) + offset.x) / self.width, (mi.Float(v) + offset.y) / self.height)
        ray, weight = self.sensor.sample_ray(0.0, sampler.next_1d(), position, sampler.next_2d())
        value, _, _ = self.integrator.sample(self.mi_scene, sampler, ray, None, True)
        rgb = mi.Color3f(value) * weight
        # Deterministic block sums (evaluated mode: no atomics) over each half of each pixel's samples.
        block = spp // 2 if spp % 2 == 0 else spp
        dr.eval(rgb)  # one kernel for all three channels
        sums = dr.block_sum(rgb, block, mode="evaluated")
        sums = np.stack([np.asarray(sums.x), np.asarray(sums.y), np.asarray(sums.z)], axis=-1).astype(np.float64)
        if block == spp:  # an odd count: one launch of one pattern
            return sums, np.zeros_like(sums)
        sums = sums.reshape(n // copies, copies, 2, 3).sum(axis=1)
        return sums[:, 0], sums[:, 1]

    def _filter_offset(self, sample: Any) -> Any:
        """Sample offsets from the pixel's corner (px) drawn from the pixel filter, separably in x and y
        (:func:`hybridgen.render.pixel_filter.warp`, in Dr.Jit)."""
        import drjit as dr
        import mitsuba as mi

        last = len(self._filter_table) - 1

        def axis(value: Any) -> Any:
            position = value * last
            index = mi.UInt32(dr.clip(dr.floor(position), 0, last - 1))
            low = dr.gather(mi.Float, self._filter_table, index)
            high = dr.gather(mi.Float, self._filter_table, index + 1)
            return dr.lerp(low, high, position - mi.Float(index))

        return mi.Point2f(axis(sample.x), axis(sample.y))


OWEN_SOBOL = True
"""Whether hybridgen's Python integrators (:mod:`hybridgen.render.pathtrace.clamped_path`: every default color render in
a JIT variant) draw their samples from :class:`hybridgen.render.pathtrace.owen_sobol.OwenSobol` (one shuffled,
Owen-scrambled Sobol pattern per pixel and launch, Cycles' Sobol-Burley) instead of the sensor's Mitsuba sampler
(``ldsampler``, :data:`hybridgen.render.pathtrace.path_trace.SAMPLER`). Mitsuba 3.9's ``ldsampler`` is biased: its
dimensions share one scramble and permutation seeds one apart, so the x of a pixel's first and third 2D sample
correlate (z = 150 over 65536 16-sample patterns, tests/render/test_owen_sobol.py), and the window room of
tools/color_quality.py rendered 0.69 % brighter than with independent random numbers (80x60, 512 spp, 8 seeds:
image mean 0.13901 vs 0.13806 +- 0.00003; Owen-Sobol 0.13806, Mitsuba's stratified / multijitter / orthogonal
0.13809 / 0.13806 / 0.13807). At equal spp Owen-Sobol is as clean as ``ldsampler`` (320x240, variance between
two seeds in 8-bit sRGB at 16 / 64 spp: window room 221 / 39.2 -> 212 / 39.2, tabletop 9.25 / 1.85 -> 8.79 /
1.89, HDRI tabletop 75.1 / 5.11 -> 47.2 / 5.56, materials 45.4 / 9.04 -> 43.9 / 9.48; independent numbers 1.5-8x
noisier) and 5-15 % cheaper per sample (Mitsuba's ``permute`` loops per dimension; stratified / multijitter /
orthogonal cost 1.3-2x ``ldsampler``'s CPU). docs/color_quality.md."""


def pattern_size(spp: int, sampler: str) -> int:
    """The sample count to give ``sampler`` for a launch of ``spp`` samples per pixel: the low-discrepancy
    sampler's patterns have 4^k points, k >= 1 (it warns and rounds up otherwise, 1 to 4); a launch of
    2^(2k+1) samples takes half of a 4^(k+1)-point pattern (a random half: the sampler shuffles the sample
    order per dimension; measured on the tabletop scene, as clean as splitting it into two full 4^k
    patterns), a launch of 1 sample a quarter of a 4-point pattern."""
    if sampler != "LowDiscrepancySampler" or spp & (spp - 1):
        return spp
    if spp == 1:
        return 4
    return spp if spp.bit_length() % 2 == 1 else spp * 2


def launch_counts(spp: int, sampler: str) -> list[int]:
    """``spp`` as a sum of sample counts ``sampler`` (a Mitsuba sampler's class name) takes exactly, largest
    first: ``spp`` itself for samplers that take any count (``IndependentSampler``); for the low-discrepancy
    sampler (``LowDiscrepancySampler``) whole patterns of 4^k points (at most :data:`MAX_PATTERN`), each as
    often as it fits, and a rest below 4 as 2 (half of a 4-point pattern) and 1. Equal counts are traced in
    one launch (:meth:`PixelTracer.trace`), each copy of a pixel with its own scramble.

    Whole patterns rather than halves of the next one: the pattern's size is compiled into the kernel, so
    the doubling adaptive rounds from 64 (64, 64, 128, 256, 512) run two kernels (64, 256) instead of four
    (a cold Dr.Jit cache compiles each in ~0.6 s), and a half pattern is a random half of its points: on the
    tabletop of tools/color_quality.py (160x120, PSNR against a 2048-spp reference, 3 seeds) 64 + 64 + 2 x 64
    samples are 49.65 dB where 64 + 64 + half of 256 were 49.19 dB and two halves of 256 48.45 dB (one
    256-point pattern: 49.56 dB)."""
    if sampler != "LowDiscrepancySampler":
        return [spp]
    out, rest = [], spp
    while rest >= 4:
        size = min(1 << (2 * ((rest.bit_length() - 1) // 2)), MAX_PATTERN)  # largest power of 4 <= rest
        out += [size] * (rest // size)
        rest %= size
    return out + [1 << bit for bit in reversed(range(rest.bit_length())) if rest >> bit & 1]


def render_adaptive(tracer: PixelTracer, plan: SamplingPlan, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Linear RGB (float32 H x W x 3) and samples per pixel (uint32 H x W) of one keypoint."""
    h, w = tracer.height, tracer.width
    if isinstance(tracer, PixelTracer):
        tracer.guide_world()
    sum_a, sum_b = np.zeros((h * w, 3)), np.zeros((h * w, 3))
    count = np.zeros(h * w, dtype=np.uint32)
    active = np.arange(h * w)
    for round_index, spp in enumerate(plan.rounds()):
        if round_index > 0:
            error = pixel_error(sum_a[active], sum_b[active], count[active])
            unconverged = np.zeros(h * w, dtype=bool)
            unconverged[active] = error >= plan.noise_threshold * CYCLES_THRESHOLD_SCALE
            keep = dilate(unconverged.reshape(h, w)).ravel()
            active = active[keep[active]]
            if len(active) == 0:
                break
        # a whole-frame tracer (scalar_rgb's) renders every pixel per call: one call per round
        per_chunk = len(active) if tracer.whole_frames else max(1, MAX_WAVEFRONT // spp)
        for chunk, start in enumerate(range(0, len(active), per_chunk)):
            pixels = active[start:start + per_chunk]
            if tracer.owen_sobol:  # one pattern per pixel, continued from round to round
                a, b = tracer.trace(pixels, spp, seed, first=count[pixels])
            else:
                a, b = tracer.trace(pixels, spp, round_seed(seed, round_index, chunk))
            sum_a[pixels] += a
            sum_b[pixels] += b
        count[active] += spp
    image = (sum_a + sum_b) / np.maximum(count, 1)[:, None]
    return image.reshape(h, w, 3).astype(np.float32), count.reshape(h, w)
