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
- ``edge_min_samples`` (hybridgen's, 0 = off): samples a pixel the denoiser cannot smooth (an edge of the denoising
  guides, :mod:`hybridgen.render.guide_edges`) gets at least, whatever its error estimate; the render's caller
  hands the edge pixels to :func:`render_adaptive`, which asks for them after the first round.
- ``edge_noise_scale`` (hybridgen's, 0 = off: ``edge_min_samples`` each): with ``edge_min_samples``, one count for all
  edge pixels, set after the first round by the root mean square of their error estimates (falling as 1 /
  sqrt(samples)) reaching the threshold divided by this (:meth:`SamplingPlan.edge_samples`). The denoiser leaves edge
  pixels as they are, so they are held to a stricter threshold; one pixel's first estimate is too noisy to stop on,
  the mean over thousands is not (measurements in :mod:`hybridgen.bproc.render_frames`).
- ``flat_noise_scale`` (hybridgen's, default 1): with ``edge_min_samples``, the pixels off the edges (which the
  denoiser smooths) stop at this many times the threshold.
- ``texture_min_samples`` (hybridgen's, 0 = off): samples the pixels of textured surfaces
  (:func:`hybridgen.render.guide_edges.textured_pixels`) get at least, in place of ``edge_min_samples`` on the texture's
  own edges; asked for after the first round, as the edges.

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

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...errors import InputError
from .pixel_tracer import PixelTracer, launch_counts, pattern_size, round_seed
from .pooled_edges import PooledEdges

__all__ = ["CYCLES_THRESHOLD_SCALE", "MAX_WAVEFRONT", "PixelTracer", "SamplingPlan", "automatic_min_samples", "dilate",
           "launch_counts", "pattern_size", "pixel_error", "render_adaptive", "round_seed"]

CYCLES_THRESHOLD_SCALE = 5.0
"""The error estimate is compared with ``noise_threshold`` times this (Cycles' own factor, in its
``Integrator::get_adaptive_sampling``; see the module docstring for the measurement)."""
MAX_WAVEFRONT = 1 << 23
"""Samples per kernel launch at most (bounds the per-sample output arrays to ~100 MB). 2^23 rather than 2^22: the
default first round at 320x240 (64 spp, 4.9 M samples) is one launch instead of two. Tabletop of
tools/color_quality.py, whole warm processes, alternating pairs, the same bytes: medians 5.17 -> 4.95 s wall over 8
pairs, 4.83 -> 4.78 s over 10 (session 12; session 11 found 4 M and 8 M within noise with the 80-spp rounds)."""


@dataclass(frozen=True)
class SamplingPlan:
    """How many samples each pixel gets; ``noise_threshold`` 0 means exactly ``max_samples`` everywhere."""

    max_samples: int = 1024
    min_samples: int = 16
    noise_threshold: float = 0.01
    edge_min_samples: int = 0
    flat_noise_scale: float = 1.0
    """With ``edge_min_samples``: pixels off the edges stop at this many times the threshold (>= 1)."""
    texture_min_samples: int = 0
    """Samples the pixels of textured surfaces get at least (0 = off), in place of ``edge_min_samples`` on the
    texture's own albedo edges."""
    edge_noise_scale: float = 0.0
    """With ``edge_min_samples``: the edge pixels' common count is set by :meth:`edge_samples` (0 = off)."""

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
        if not (math.isfinite(self.flat_noise_scale) and self.flat_noise_scale >= 1):
            raise InputError(f"flat_noise_scale must be >= 1, got {self.flat_noise_scale}")
        if not 0 <= self.texture_min_samples <= self.max_samples:
            raise InputError(f"texture_min_samples must be in 0..samples ({self.max_samples}), "
                             f"got {self.texture_min_samples}")
        if not (math.isfinite(self.edge_noise_scale) and self.edge_noise_scale >= 0):
            raise InputError(f"edge_noise_scale must be >= 0 (0 = off), got {self.edge_noise_scale}")
        if not 0 <= self.edge_min_samples <= self.max_samples:
            raise InputError(f"edge_min_samples must be in 0..samples ({self.max_samples}), "
                             f"got {self.edge_min_samples}")

    @property
    def adaptive(self) -> bool:
        return self.noise_threshold > 0

    @property
    def texture_floor(self) -> bool:
        """Whether ``texture_min_samples`` gives some pixels more samples than the first round."""
        return self.adaptive and self.texture_min_samples > self.rounds()[0]

    @property
    def edge_floor(self) -> bool:
        """Whether ``edge_min_samples`` gives some pixels more samples than the first round."""
        return self.adaptive and self.edge_min_samples > self.rounds()[0]

    def edge_samples(self, errors: np.ndarray, samples: int) -> int:
        """Every edge pixel's samples: the even count where the root mean square of ``errors`` (after ``samples``)
        reaches the threshold x 5 / ``edge_noise_scale``, in [2 x first round, ``edge_min_samples``] (that if 0)."""
        most = self.edge_min_samples
        if self.edge_noise_scale == 0 or len(errors) == 0:
            return most
        with np.errstate(over="ignore", invalid="ignore"):
            needed = samples * float(np.mean(np.square(errors))) / \
                (self.noise_threshold * CYCLES_THRESHOLD_SCALE / self.edge_noise_scale) ** 2
        if not math.isfinite(needed):  # a non-finite estimate says nothing: the floor
            return most
        least = min(2 * self.rounds()[0], most)
        return int(min(max(math.ceil(needed / 2) * 2, least), most))

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


def _pixel_mask(found: np.ndarray | None, size: int) -> np.ndarray:
    """A caller's pixels (bool H x W, or None: none) as a flat bool mask of ``size``."""
    return np.zeros(size, dtype=bool) if found is None else np.asarray(found, dtype=bool).ravel()


def render_adaptive(tracer: PixelTracer, plan: SamplingPlan, seed: int,
                    edges: Callable[[], np.ndarray | None] | None = None,
                    pool: PooledEdges | None = None,
                    textured: Callable[[], np.ndarray | None] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Linear RGB (float32 H x W x 3) and samples per pixel (uint32 H x W) of one keypoint. With the plan's
    ``edge_min_samples``, ``edges`` is called once, after the first round (so that the caller can find them
    meanwhile), for the pixels (bool H x W, or None: none) that get at least that many samples. With ``pool`` as
    well (a tracer with hybridgen's Owen-Sobol sampler), those pixels' samples from the second round on are also
    pooled with their neighbours' (:mod:`hybridgen.render.pathtrace.pooled_edges`; ``pool.started`` tells whether
    there were any). With the plan's ``texture_min_samples``, ``textured`` is called once, after the first round,
    for the pixels of textured surfaces (bool H x W, or None) that get at least that many - edge pixels among them
    that instead of ``edge_min_samples``."""
    h, w = tracer.height, tracer.width
    if isinstance(tracer, PixelTracer):
        tracer.guide_world()
    sum_a, sum_b = np.zeros((h * w, 3)), np.zeros((h * w, 3))
    count = np.zeros(h * w, dtype=np.uint32)
    active = np.arange(h * w)
    floor: np.ndarray | None = None  # the edge pixels (flat bool), once asked for
    texture: np.ndarray | None = None  # the textured pixels (flat bool), once asked for
    edge_target = plan.edge_min_samples  # the samples the edge floor gives (plan.edge_samples, once known)
    finished = np.zeros(h * w, dtype=bool)  # pixels whose edge floor ended with a partial round: done
    if pool is not None:
        pool.reset()
        if not getattr(tracer, "owen_sobol", False):
            pool = None
    for round_index, spp in enumerate(plan.rounds()):
        groups: list[tuple[np.ndarray, int]] = []  # (pixels, samples each) traced this round; none: all active
        if round_index > 0:
            rows = slice(None) if len(active) == h * w else active  # all: views, not copies
            error = pixel_error(sum_a[rows], sum_b[rows], count[rows])
            if plan.edge_floor and edges is not None and floor is None:
                floor = _pixel_mask(edges(), h * w)
            threshold = plan.noise_threshold * CYCLES_THRESHOLD_SCALE
            if floor is not None and plan.flat_noise_scale != 1:  # the denoiser smooths the pixels off the edges
                threshold = np.where(floor[active], threshold, threshold * plan.flat_noise_scale)
            unconverged = np.zeros(h * w, dtype=bool)
            unconverged[active] = error >= threshold
            keep = dilate(unconverged.reshape(h, w)).ravel()
            if plan.texture_floor and textured is not None and texture is None:
                texture = _pixel_mask(textured(), h * w)
            if texture is not None:
                keep |= texture & (count < plan.texture_min_samples)
            floor_only = np.zeros(h * w, dtype=bool)  # pixels kept for the edge floor alone
            if floor is not None:  # an edge of a texture gets the texture's minimum (guide_edges.textured_pixels)
                edge = floor if texture is None else floor & ~texture
                if round_index == 1:  # every pixel has had the first round: one count for the edges
                    edge_target = plan.edge_samples(error[edge[active]], plan.rounds()[0])
                floor_only = edge & (count < edge_target) & ~keep
                keep |= floor_only
            keep &= ~finished
            active = active[keep[active]]
            if len(active) == 0:
                break
            if pool is not None and floor is not None and floor.any():
                if not pool.started:  # the edges are known from the second round on
                    pool.start(floor, sum_a + sum_b, count)
                pool.round(active)
            short = floor_only[active] & (count[active] + spp > edge_target)  # a partial round ends their floor
            if short.any():  # (active pixels share one count)
                finished[active[short]] = True
                groups = [(active[~short], spp), (active[short], edge_target - int(count[active[short][0]]))]
        chunk = 0
        for pixels_of, samples in groups or [(active, spp)]:
            # a whole-frame tracer (scalar_rgb's) renders every pixel per call: one call per group
            per_chunk = len(pixels_of) if tracer.whole_frames else max(1, MAX_WAVEFRONT // samples)
            for start in range(0, len(pixels_of), per_chunk):
                pixels = pixels_of[start:start + per_chunk]
                if tracer.owen_sobol:  # one pattern per pixel, continued from round to round
                    pooling = {"pool": pool} if pool is not None and pool.started else {}
                    a, b = tracer.trace(pixels, samples, seed, first=count[pixels], **pooling)
                else:
                    a, b = tracer.trace(pixels, samples, round_seed(seed, round_index, chunk))
                chunk += 1
                rows = slice(start, start + len(pixels)) if len(pixels_of) == h * w else pixels  # all: no index lists
                sum_a[rows] += a
                sum_b[rows] += b
            count[pixels_of if len(pixels_of) < h * w else slice(None)] += samples
    image = (sum_a + sum_b) / np.maximum(count, 1)[:, None]
    return image.reshape(h, w, 3).astype(np.float32), count.reshape(h, w)
