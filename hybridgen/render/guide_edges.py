"""Pixels the denoiser cannot smooth: where the denoising guides (albedo, normals) change from one pixel to the next.

Open Image Denoise, given clean guides, averages a pixel with neighbours whose guides look alike. Across a
silhouette, a crease or an albedo edge it keeps the two sides apart, and a pixel that straddles one (its filter
footprint covers both sides, so its guides are a mix no neighbour shares) keeps most of its own noise. Adaptive
sampling's error estimate does not know that: such a pixel stops as soon as its raw noise is as low as a flat
pixel's, whose noise the denoiser then removes. :func:`guide_edges` finds them, so that adaptive sampling can give
them a higher minimum (:attr:`hybridgen.render.pathtrace.adaptive_sampling.SamplingPlan.edge_min_samples`).

A pixel is an edge pixel when its albedo differs from one of its 8 neighbours' by more than :data:`ALBEDO_STEP`
(sum of the absolute RGB differences, linear albedo 0..1) or its normal by more than :data:`NORMAL_STEP` (sum of
the absolute xyz differences of the box-filtered unit normals; the background's normal is 0). With the guides
of :mod:`hybridgen.render.denoise_guides` (filtered like the color's pixels) that marks a band about three pixels
wide along every silhouette and crease: 9 % of the pixels of BlenderProc's ``basics/basic`` frame 0, which
hold 60 % of the denoised image's squared error against a converged reference at BlenderProc's default
sampling (docs/blenderproc.md, "Speed").
"""
from __future__ import annotations

import numpy as np

from .pathtrace.adaptive_sampling import dilate

ALBEDO_STEP = 0.05
"""Largest albedo difference (sum over RGB) between neighbours that is not an edge."""
NORMAL_STEP = 0.1
"""Largest normal difference (sum over xyz) between neighbours that is not an edge (about 6 degrees)."""
TEXTURE_STEP = ALBEDO_STEP / 4
"""Smallest albedo difference (sum over RGB) between neighbours that marks a textured surface (:func:`textured_pixels`)."""
GEOMETRIC_EDGE_STEP = NORMAL_STEP
"""Normal difference (sum over xyz) between neighbours above which a pixel lies on a silhouette or crease: never a
textured pixel (:func:`textured_pixels`), whatever its albedo does."""


def _largest_step(image: np.ndarray) -> np.ndarray:
    """Per pixel of an H x W x C image, the largest sum of absolute channel differences to any of its 8
    neighbours (neighbours beyond the border repeat the edge pixel: no step). A step between two pixels is theirs
    both, so four directions are differenced, each once (half the work of eight; the same values)."""
    height, width = image.shape[:2]
    image = np.asarray(image, dtype=np.float32)
    largest = np.zeros((height, width), dtype=np.float32)
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):  # from pixel p to its neighbour q = p + (dy, dx)
        left, right = max(0, -dx), width - max(0, dx)  # the columns of the p that have such a q
        near, far = largest[:height - dy, left:right], largest[dy:, left + dx:right + dx]
        step = np.abs(image[dy:, left + dx:right + dx] - image[:height - dy, left:right]).sum(axis=2)
        np.maximum(near, step, out=near)
        np.maximum(far, step, out=far)
    return largest


def edge_strength(albedo: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Float32 H x W: each pixel's largest guide step to a neighbour in units of the edge thresholds,
    ``max(albedo step / ALBEDO_STEP, normal step / NORMAL_STEP)`` (guides H x W x 3 each, see the module
    docstring); above 1 is an edge pixel."""
    return _strength(_steps(albedo), _steps(normals))


def edge_strength_and_texture(albedo: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(:func:`edge_strength`, :func:`textured_pixels`) of the guides, each guide's steps computed once."""
    albedo_steps, normal_steps = _steps(albedo), _steps(normals)
    return _strength(albedo_steps, normal_steps), _textured(albedo_steps, normal_steps)


def textured_pixels(albedo: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Bool H x W: the pixels on or beside a textured surface - an albedo step to a neighbour above
    :data:`TEXTURE_STEP`, grown by one pixel - that are not on a silhouette or crease (a normal step above
    :data:`GEOMETRIC_EDGE_STEP`).

    Open Image Denoise needs more samples there than on a uniform surface to keep the texture (BlenderProc's
    ``basics/material_manipulation``: 52.9 -> 55.3 dB against the converged image with these pixels at 64 spp instead
    of 32, for 11 % more samples; untextured ``basics/basic`` +0.04 dB for 1 %), but no more on the texture's own
    albedo edges than between them: adaptive sampling gives these pixels the texture's minimum in place of the edge
    minimum (:func:`hybridgen.render.pathtrace.adaptive_sampling.render_adaptive`). There the wood of
    material_manipulation has as much noise per sample on its grain's edges as between them; with the grain's edges at
    the edge minimum (256 spp) they held 52 % of the samples for 13 % of the error. At 64 spp: 55.34 -> 54.14 dB
    (BlenderProc 53.36) for 62 % of the frame's sampling time; basics/basic 56.44 -> 56.43 dB, the same samples."""
    return _textured(_steps(albedo), _steps(normals))


def _steps(guide: np.ndarray) -> np.ndarray:
    """:func:`_largest_step` of a guide, a non-finite value counting as 0."""
    return _largest_step(np.nan_to_num(np.asarray(guide, dtype=np.float32)))


def _strength(albedo_steps: np.ndarray, normal_steps: np.ndarray) -> np.ndarray:
    return np.maximum(albedo_steps / ALBEDO_STEP, normal_steps / NORMAL_STEP)


def _textured(albedo_steps: np.ndarray, normal_steps: np.ndarray) -> np.ndarray:
    return dilate(albedo_steps > TEXTURE_STEP) & ~(normal_steps > GEOMETRIC_EDGE_STEP)


def guide_edges(albedo: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Bool H x W: the pixels whose albedo or normal guide (H x W x 3 each, see the module docstring) steps to a
    neighbour's."""
    return edge_strength(albedo, normals) > 1.0
