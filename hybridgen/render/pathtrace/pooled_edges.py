"""Edge pixels' raw colors from their own samples and their neighbours' (a pooled pixel estimate).

Each camera sample of pixel ``s`` lands at an offset drawn from the pixel filter around ``s``'s centre
(:mod:`hybridgen.render.pixel_filter`, importance-sampled), and the pixel's value is the mean of its own samples.
The filter's support is wider than a pixel (Cycles' Blackman-Harris, ``filter_width`` 1.5: +-1.5 px), so samples of
the neighbours land inside pixel ``t``'s filter too. Pooling them with the balance heuristic over the pixels'
sample densities keeps ``t``'s expectation and lowers its noise: a sample at ``x`` from any of the sources
``t + SHAPE`` (``t`` and its four neighbours) counts for ``t`` with weight

    f(x) * p(x - t) / sum_{o in SHAPE, t + o contributes} p(x - t - o),     p = the filter's normalised density,

each round's sources having equal counts (a source that does not contribute in a round is left out of that round's
sums for every target; ``t`` itself must contribute - its own samples cover its whole support). The pooled value is
the weighted mean: the weighted sum over the samples of all rounds divided by the sum of their weights (whose
expectation is ``t``'s own sample count). Dividing by the weights rather than by the count makes it exact where every
sample agrees (the weights of a finite set of samples do not sum to their expectation: divided by the count, a
uniformly lit surface scattered by a few % at 64 spp), at a bias of order 1/samples elsewhere. Its noise is
correlated between neighbours, which would mislead the denoiser, so it only replaces the raw samples where those are
mixed back on guide edges (:mod:`hybridgen.render.edge_blend`); the denoiser still gets the per-pixel means.

It lowers the noise that comes from the light (indirect light: 93 % of the edge pixels' variance on basics/basic);
where a pixel's variance is only which side of a sharp edge its samples fall on, Owen-Sobol's stratified samples
already cancel most of it and the pooled value can be worse (a directly seen emitting panel, 64 spp: variance along
the column the edge crosses 4.1e-4 pooled vs 1.3e-4 own, along the column beside it 0.3e-4 vs 1.4e-4). Across seeds on
a lit cube's edges (tests/render/test_pooled_edges.py) its variance is 0.78 times the pixels' own in sRGB values
(0.94 in linear light, where a few bright pixels dominate; 0.81 before the Principled BSDF drew lobe and direction
from one 2D sample, :func:`~.principled_sampling.split`, which stratified the pixels' own samples better).

Edges are known after adaptive sampling's first round (:mod:`hybridgen.render.guide_edges`), so rounds from the
second on are pooled, the first counted as the pixel's own mean. Measured on BlenderProc's ``basics/basic`` (frame 0,
512 x 512, minimum 32 spp, 256 on edges; PSNR of the 8-bit colors against the converged image with the references'
noise taken out, docs/blenderproc.md "Speed"): the edge pixels' squared error 0.74 -> 0.46 with every round pooled
(3 x 3 sources); whole image 56.46 -> 57.09 dB with the edges mixed at 0.7, 57.04 dB with the plus-shaped sources
here, 56.94 dB leaving out the first round as here, 56.95 dB as the weighted mean.

Sums (RGB and the weight) are accumulated in the tracing kernel as 64-bit fixed point (:data:`SCALE`): integer
addition is associative, so the result does not depend on which thread adds first - the same bytes on every run.
Costs ~20 ns a sample on the 2-core machine (~10 % of an edge sample), only in the launches of contributing pixels.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

SHAPE = ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1))
"""The sources pooled into a target, as offsets (du, dv) from it: the target and its four neighbours (3 x 3 sources
score 0.05 dB higher on basics/basic and cost 27 instead of 15 atomic additions a sample)."""
REACH = sorted({(a + c, b + d) for a, b in SHAPE for c, d in SHAPE})
"""Offsets from a source of the sources its samples' weights depend on (13: the shape's sum with itself)."""
PAD = 2
"""Pixels of margin around the accumulator (targets up to one pixel outside the image, never read)."""
SCALE = float(1 << 28)
"""Fixed-point scale of the accumulated radiance (linear RGB x weight <= 1): 2^-28 resolution, headroom for
sums of ~6e10."""
CHANNELS = 4
"""Accumulated per pixel: the weighted R, G, B and the weight."""
BH = (0.35875, 0.48829, 0.14128, 0.01168)
"""The four Blackman-Harris coefficients (:func:`hybridgen.render.pixel_filter.blackman_harris`)."""


def filter_density(x: Any, width: float, shift: float = 0.0) -> Any:
    """The pixel filter's normalised density (1/px, integrates to 1) at ``x - shift`` px from a pixel centre: the
    Blackman-Harris window of ``width`` (support +-width) over its integral ``0.35875 * 2 width``. Dr.Jit Float
    ``x``; ``shift`` a Python number (the angle's cosine comes from one sine and cosine of ``x``)."""
    import drjit as dr

    k = math.pi / width
    sin_x, cos_x = dr.sincos(x * k)
    c1 = cos_x * math.cos(k * shift) + sin_x * math.sin(k * shift)  # cos(pi (x - shift) / width)
    value = BH[0] + BH[1] * c1 + BH[2] * (2 * c1 * c1 - 1) + BH[3] * (4 * c1 * c1 * c1 - 3 * c1)
    return dr.select(dr.abs(x - shift) < width, value * (1.0 / (BH[0] * 2 * width)), 0.0)


class PooledEdges:
    """The pooled estimate of one keypoint's edge pixels (``width`` x ``height`` px, the color's ``filter_width``):
    :meth:`reset` per keypoint, :meth:`start` after its first round, :meth:`round` before each later one,
    :meth:`add` in each launch's kernel, :meth:`image` at the end. One keypoint at a time."""

    def __init__(self, width: int, height: int, filter_width: float) -> None:
        import drjit as dr
        import mitsuba as mi

        if filter_width <= 0:
            raise ValueError("pooling needs a pixel filter wider than the pixel (filter_width > 0)")
        self.width, self.height, self.filter_width = width, height, float(filter_width)
        self._stride = width + 2 * PAD
        self._sums = dr.zeros(mi.UInt64, CHANNELS * (height + 2 * PAD) * self._stride)
        self._targets: np.ndarray | None = None  # bool H*W: the pixels pooled (the edges)
        self._sources: np.ndarray | None = None  # bool H*W: pixels whose samples are pooled (targets and neighbours)
        self._first: np.ndarray | None = None  # float64 H*W x 4: the first round's own sums (RGB) and counts
        self._bits: np.ndarray | None = None  # uint32 H*W: per source, which of its REACH contributes this round

    def reset(self) -> None:
        """Forget the last keypoint (its accumulator is cleared by :meth:`start`)."""
        self._targets = self._sources = self._first = self._bits = None

    def start(self, targets: np.ndarray, first_sums: np.ndarray, first_counts: np.ndarray) -> None:
        """``targets`` (bool H*W, flat) get pooled values; ``first_sums`` (H*W x 3) and ``first_counts`` (H*W) are the
        first round's sums of every pixel's own samples and their number (counted as they are, weight 1 each)."""
        import drjit as dr
        import mitsuba as mi

        self._targets = np.asarray(targets, dtype=bool).ravel().copy()
        grid = self._padded(self._targets)
        sources = np.zeros_like(grid)
        for du, dv in SHAPE:
            sources |= np.roll(np.roll(grid, dv, axis=0), du, axis=1)
        self._sources = sources[PAD:-PAD, PAD:-PAD].ravel()
        self._first = np.concatenate([np.asarray(first_sums, dtype=np.float64),
                                      np.asarray(first_counts, dtype=np.float64).reshape(-1, 1)], axis=1)
        self._sums = dr.zeros(mi.UInt64, CHANNELS * (self.height + 2 * PAD) * self._stride)

    @property
    def started(self) -> bool:
        return self._targets is not None

    def round(self, active: np.ndarray) -> None:
        """The next round traces ``active`` (flat indices): each contributing source learns which of the sources
        within its reach contribute too."""
        assert self._sources is not None
        on = np.zeros(self.width * self.height, dtype=bool)
        on[active] = True
        grid = self._padded(on & self._sources)
        bits = np.zeros((self.height, self.width), dtype=np.uint32)
        for bit, (du, dv) in enumerate(REACH):
            bits |= grid[PAD + dv:PAD + dv + self.height, PAD + du:PAD + du + self.width].astype(np.uint32) << bit
        self._bits = bits.ravel()

    def add(self, pixels: np.ndarray, local: Any, u: Any, v: Any, offset: Any, rgb: Any) -> None:
        """Records, in the launch's kernel, the pooled contributions of its samples: ``pixels`` (flat indices, the
        launch's; those that do not contribute this round add nothing), ``local`` each sample's index into them,
        ``u``/``v`` its pixel (UInt32),
        ``offset`` its offset from the pixel's corner (Point2f, px), ``rgb`` its value (Color3f, linear)."""
        import drjit as dr
        import mitsuba as mi

        assert self._bits is not None
        bits = dr.gather(mi.UInt32, mi.UInt32(np.ascontiguousarray(self._bits[pixels])), local)
        contributes = {o: mi.Float((bits >> index) & 1) for index, o in enumerate(REACH)}
        cx, cy = offset.x - 0.5, offset.y - 0.5
        reach_x = sorted({du for du, _ in REACH})
        px = {d: filter_density(cx, self.filter_width, d) for d in reach_x}
        py = {d: filter_density(cy, self.filter_width, d) for d in reach_x}
        valid = dr.isfinite(rgb.x) & dr.isfinite(rgb.y) & dr.isfinite(rgb.z)
        base = mi.Int32((v + PAD) * self._stride + u + PAD)
        for tu, tv in SHAPE:  # this sample's targets: the source is target + (-tu, -tv), in the shape too
            denominator = mi.Float(0.0)
            for du, dv in SHAPE:
                denominator = dr.fma(contributes[(tu + du, tv + dv)] * px[tu + du], py[tv + dv], denominator)
            weight = contributes[(0, 0)] * contributes[(tu, tv)] * px[tu] * py[tv] / dr.maximum(denominator, 1e-30)
            live = valid & (weight > 0)
            target = mi.UInt32(base + tv * self._stride + tu) * CHANNELS
            for channel, value in enumerate((rgb.x, rgb.y, rgb.z, 1.0)):
                fixed = mi.UInt64(dr.maximum(value * weight, 0.0) * SCALE + 0.5)
                dr.scatter_reduce(dr.ReduceOp.Add, self._sums, fixed, target + channel, live,
                                  mode=dr.ReduceMode.Local)

    @property
    def sums(self) -> Any:
        """The Dr.Jit accumulator (evaluate it with the launch's outputs)."""
        return self._sums

    def image(self) -> np.ndarray:
        """Float32 H x W x 3: the pooled linear RGB at the targets (the weighted mean), NaN elsewhere."""
        assert self._targets is not None and self._first is not None
        pooled = np.asarray(self._sums, dtype=np.uint64).reshape(self.height + 2 * PAD, self._stride, CHANNELS)
        pooled = pooled[PAD:-PAD, PAD:-PAD].reshape(-1, CHANNELS).astype(np.float64) / SCALE
        out = np.full((self.width * self.height, 3), np.nan, dtype=np.float32)
        t = self._targets
        total = self._first[t] + pooled[t]
        out[t] = total[:, :3] / np.maximum(total[:, 3:], 1e-12)
        return out.reshape(self.height, self.width, 3)

    def _padded(self, flat: np.ndarray) -> np.ndarray:
        return np.pad(np.asarray(flat, dtype=bool).reshape(self.height, self.width), PAD)
