"""Denoised colors mixed back with the raw samples on strong edges of the denoising guides.

Open Image Denoise cannot average a pixel that straddles a silhouette or a strong albedo edge with its neighbours
(:mod:`hybridgen.render.guide_edges`): such a pixel keeps its own noise, and the denoiser's output there is also
biased, a little off in a way more samples do not remove. Measured on BlenderProc's ``basics/basic`` (frame 0,
512 x 512, at least 64 spp and edge pixels at 256; the error of each pixel against the converged image, the two
1024-spp references' own noise taken out, see docs/blenderproc.md "Speed"), mean over the pixels of each class,
in 8-bit levels squared:

| edge strength (:func:`~hybridgen.render.guide_edges.edge_strength`) | share of pixels | raw | denoised |
|---|---|---|---|
| below 0.5 (flat) | 90 % | 0.71 | 0.08 |
| 2 - 4 | 2.0 % | 0.65 | 0.47 |
| 4 - 8 | 2.3 % | 0.76 | 0.66 |
| 8 - 16 | 2.2 % | 0.81 | 0.83 |
| 16 and more | 1.8 % | 1.12 | 1.37 |

Where the guides step by at least :data:`STRONG_EDGE` times the edge threshold, the raw value is as good as the
denoised one or better, and the two errors are partly independent (noise in one, bias in the other), so an even mix
beats either: ``colors = weight x raw + (1 - weight) x denoised`` there, with ``weight`` 0.5
(:attr:`hybridgen.render.pathtrace.path_trace_settings.PathTraceSettings.edge_raw_weight`). Whole-image PSNR
against the converged image, 8-bit colors, weights 0.25 / 0.5 / 0.75 / 1 from strength 4: basics/basic at 64 spp
minimum 56.47 dB unmixed, 56.62 / 56.69 / 56.66 / 56.55; at 32 spp minimum 56.01 dB, 56.21 / 56.35 / 56.36 / 56.26;
camera_sampling at 64: 56.68 dB, 56.90 / 57.03 / 57.00 / 56.84; at 32: 55.96 dB, 56.27 / 56.49 / 56.51 / 56.37.
From strength 2, 8 or 16 instead of 4 the best mixes are within 0.05 dB of these. (Those mixes were of the 8-bit
colors; the producer mixes linear light before encoding: 56.46 dB on basics/basic and 56.57 on camera_sampling at the
32 spp minimum and weight 0.5.)

Where the tracer pools the edge pixels' samples with their neighbours' (:mod:`hybridgen.render.pathtrace.pooled_edges`:
the same expectation, less noise), that pooled estimate is mixed in instead, on every edge pixel (strength above 1,
the pixels adaptive sampling gives the edge floor): basics/basic at the 32 spp minimum, weight 0.5 / 0.6 / 0.7, 56.91
/ 56.94 / 56.92 dB, camera_sampling 56.77 / 56.81 / 56.80 dB.
"""
from __future__ import annotations

import numpy as np

STRONG_EDGE = 4.0
"""Edge strength (guide step over the edge threshold) from which raw samples are mixed in."""


def mix_raw_on_edges(denoised: np.ndarray, raw: np.ndarray, strength: np.ndarray, weight: float,
                     pooled: np.ndarray | None = None) -> np.ndarray:
    """``denoised`` (linear RGB, float32 H x W x 3) with ``weight`` of ``raw`` (the same image before denoising)
    mixed in where ``strength`` (H x W, :func:`~hybridgen.render.guide_edges.edge_strength`) is at least
    :data:`STRONG_EDGE`; ``weight`` 0 returns ``denoised`` itself. Given ``pooled`` (the edge pixels' pooled
    estimate, NaN elsewhere: :mod:`hybridgen.render.pathtrace.pooled_edges`), that is mixed in instead, at every
    pixel it covers."""
    if weight <= 0:
        return denoised
    if pooled is not None:
        where = np.isfinite(pooled).all(axis=2)
        source = np.asarray(pooled, dtype=np.float32)
    else:
        where = np.asarray(strength) >= STRONG_EDGE
        source = np.asarray(raw, dtype=np.float32)
    out = np.array(denoised, dtype=np.float32, copy=True)
    out[where] = (weight * source[where] + (1.0 - weight) * out[where]).astype(np.float32)
    return out
