"""The pixel reconstruction filter of the path-traced color: Cycles' default, a Blackman-Harris window.

Cycles (and so BlenderProc) reconstructs pixels with a Blackman-Harris filter of ``filter_width`` 1.5 px,
which Cycles evaluates over a support of twice that width (``[-1.5, 1.5]`` px around the pixel centre, per
axis, separably). Like Cycles, hybridgen *importance-samples* the filter: each camera sample's offset from
the pixel centre is drawn from the filter's normalised 1D profile along x and along y (inverse CDF), and
the sample counts for its own pixel only, with weight 1. The pixel value is then the filter-weighted mean
of the radiance around the pixel centre, exactly as with a splatting filter, but the pixels' noise stays
independent (a splatting filter correlates neighbours' noise, which defeats the denoiser), and adaptive
sampling still counts samples per pixel.

The filter is symmetric about the pixel centre, so color pixel (u, v) stays centred on the label sample
(u, v) (labels are exact at pixel centres). ``width`` 0 gives the one-pixel box filter (offsets uniform in
``[-0.5, 0.5]``), Mitsuba's plain film footprint.
"""
from __future__ import annotations

import math

import numpy as np

DEFAULT_WIDTH = 1.5
"""Cycles' default ``filter_width`` (px) for its Blackman-Harris filter (support: twice this)."""
TABLE_SIZE = 1024
"""Entries of the inverse-CDF table the sample warp interpolates."""
ROW_BLOCK = 16
"""Output rows :func:`filter_supersampled` sums at a time (the same sums in the same order, cache-sized)."""


def blackman_harris(x: np.ndarray, width: float) -> np.ndarray:
    """The Blackman-Harris window of Cycles' ``filter_width`` ``width`` at offsets ``x`` (px): support
    ``|x| <= width`` (zero outside), peak 1 at 0."""
    x = np.asarray(x, dtype=np.float64)
    phase = 2 * math.pi * (x / (2 * width) + 0.5)
    value = 0.35875 - 0.48829 * np.cos(phase) + 0.14128 * np.cos(2 * phase) - 0.01168 * np.cos(3 * phase)
    return np.where(np.abs(x) <= width, value, 0.0)


def inverse_cdf_table(width: float, size: int = TABLE_SIZE) -> np.ndarray:
    """Offsets (px, float64, ``size + 1`` values from ``-width`` to ``width``) at CDF values 0, 1/size, ...,
    1 of the filter's 1D profile; ``width`` 0: the box filter's ``[-0.5, 0.5]``."""
    if width <= 0:
        return np.linspace(-0.5, 0.5, size + 1)
    x = np.linspace(-width, width, 8 * size + 1)
    density = blackman_harris(x, width)
    cdf = np.concatenate([[0.0], np.cumsum((density[1:] + density[:-1]) / 2)])
    cdf /= cdf[-1]
    return np.interp(np.linspace(0.0, 1.0, size + 1), cdf, x)


def warp(table: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Offsets (px) of uniform samples ``u`` in [0, 1): linear interpolation in ``table``."""
    position = np.asarray(u, dtype=np.float64) * (len(table) - 1)
    index = np.clip(np.floor(position).astype(np.int64), 0, len(table) - 2)
    return table[index] + (position - index) * (table[index + 1] - table[index])


def pixel_weights(width: float, offsets: np.ndarray) -> np.ndarray:
    """Normalised 1D weights of the filter at sub-pixel ``offsets`` (px from a pixel centre) - what a
    supersampled image (e.g. the denoiser's raster guides) is averaged with to match the color's filter."""
    weights = blackman_harris(offsets, width) if width > 0 else (np.abs(offsets) <= 0.5).astype(np.float64)
    return weights / weights.sum()


def filter_supersampled(image: np.ndarray, factor: int, width: float) -> np.ndarray:
    """Pixels (float32 H x W x C) of an image supersampled ``factor`` times per axis (H*factor x W*factor x C,
    sub-pixel centres tiling each pixel), weighted by the filter around each pixel centre, separably - what
    the path tracer's pixel (u, v) averages. Sub-pixels beyond the image border repeat the edge."""
    f = int(factor)
    reach = int(math.ceil(max(width, 0.5) * f))  # fine pixels on each side of a pixel's own block
    taps = np.arange(-reach, reach + f)  # fine indices relative to the first one of the pixel's block
    weights = pixel_weights(width, (taps + 0.5) / f - 0.5)
    fine = np.pad(np.asarray(image, dtype=np.float32), ((reach, reach), (reach, reach), (0, 0)), mode="edge")
    height, width_px = image.shape[0] // f, image.shape[1] // f

    def along(array: np.ndarray, axis: int, count: int) -> np.ndarray:
        out = np.zeros(array.shape[:axis] + (count,) + array.shape[axis + 1:], dtype=np.float64)
        rows = out.shape[0]
        for first in range(0, rows, ROW_BLOCK):  # a block of output rows at a time: its sums stay in cache
            last = min(first + ROW_BLOCK, rows)
            block = out[first:last]
            term = np.empty_like(block)
            for tap, weight in zip(taps, weights):
                if weight > 0:  # fine pixels reach + tap, reach + tap + f, ... as a strided view (no copy)
                    start = reach + tap
                    if axis == 0:
                        view = array[start + first * f:start + last * f:f]
                    else:
                        view = array[first:last, start:start + count * f:f]
                    np.multiply(view, weight, out=term)
                    block += term
        return out

    return np.ascontiguousarray(along(along(fine, 0, height), 1, width_px), dtype=np.float32)
