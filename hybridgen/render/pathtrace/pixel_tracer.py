"""The pixel tracer of adaptive sampling: chosen pixels of the loaded Mitsuba scene traced with a given number of
samples each, their two halves summed apart (:mod:`hybridgen.render.pathtrace.adaptive_sampling` compares them),
with hybridgen's Owen-scrambled Sobol samples and Cycles' pixel filter; and the sample counts a launch can take."""
from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from .. import pixel_filter
from .owen_sobol import OwenSobol, mix
from .pooled_edges import PooledEdges

LAUNCH_STREAM = 1 << 20
"""Round index (never reached by adaptive rounds) whose seeds the second and later launches of one trace use."""
MAX_PATTERN = 1024
"""Most samples one low-discrepancy pattern gives a pixel (4^5 points); more are traced as several patterns."""

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


def round_seed(seed: int, round_index: int, chunk: int) -> int:
    """Sampler seed of one launch: a pure function of the keypoint seed, the round and the chunk."""
    return int(np.random.SeedSequence([int(seed), round_index, chunk]).generate_state(1)[0])


class PixelTracer:
    """Traces chosen pixels of the loaded Mitsuba scene (JIT variants only)."""

    whole_frames = False
    """Traces only the pixels asked for, so :func:`render_adaptive` splits large rounds into launches of at most
    :data:`~hybridgen.render.pathtrace.adaptive_sampling.MAX_WAVEFRONT` samples."""

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

    def trace(self, pixels: np.ndarray, spp: int, seed: int, first: np.ndarray | None = None,
              pool: PooledEdges | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Sums of linear RGB over the first and the second half of ``spp`` samples of every pixel in
        ``pixels`` (flat indices ``v * width + u``): two float64 arrays of shape (len(pixels), 3).

        hybridgen's Owen-Sobol sampler (:data:`OWEN_SOBOL`) gives each pixel one pattern per ``seed`` (the
        keypoint's: adaptive rounds continue it) and traces its samples number ``first`` (per pixel, 0 if not
        given) to ``first + spp - 1``: a pixel's samples of all rounds are one prefix of its sequence, every
        power-of-two part of it stratified. The sensor's Mitsuba sampler may only accept some sample counts
        (stratified patterns: powers of two for ``ldsampler``), so ``spp`` is split into counts it accepts
        (:func:`launch_counts`); equal counts are one launch (a pattern per count and pixel), each launch with its
        own seed derived from ``seed``; each pattern's first half of samples goes to the first sum.
        An odd ``spp`` (fixed-count rendering only) leaves the odd sample in the first sum. With ``pool`` (Owen-Sobol
        only) the samples of its contributing pixels are also pooled into its edge pixels
        (:mod:`hybridgen.render.pathtrace.pooled_edges`)."""
        if self.owen_sobol:
            return self._launch(pixels, spp, 1, seed, np.zeros(len(pixels), np.uint32) if first is None else first,
                                pool)
        if pool is not None:
            raise ValueError("pooled edges need hybridgen's Owen-Sobol sampler")
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
                first: np.ndarray | None = None, pool: PooledEdges | None = None) -> tuple[np.ndarray, np.ndarray]:
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
        if pool is not None:
            pool.add(pixels, local, u, v, offset, rgb)
        # Deterministic block sums (evaluated mode: no atomics) over each half of each pixel's samples.
        block = spp // 2 if spp % 2 == 0 else spp
        dr.eval(rgb, *([] if pool is None else [pool.sums]))  # one kernel for all three channels (and the pool)
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
