"""Pure comparisons of one frame as two engines rendered it (hybridgen vs BlenderProc), for
tools/compare_with_blenderproc.py.

Inputs are BlenderProc's data-dict forms: depth float32 (H, W) in m along the optical axis (background 1e10 or
more), normals float32 (H, W, 3) in Blender camera axes encoded ``0.5 n + 0.5``, instance maps integer (H, W)
(0: background), colors uint8 (H, W, 3) sRGB. Angles in degrees, distances in m.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from hybridgen.render.pathtrace.material_emission import srgb_decode

BACKGROUND_DEPTH = 1e9
"""Depth at or above this (m) is background (Cycles' Z pass writes 1e10 there)."""
DEPTH_JUMP = 0.02
"""A relative depth step larger than this between neighbouring pixels marks a silhouette."""
CREASE_DEGREES = 2.0
"""Neighbouring normals further apart than this (degrees) mark a crease: a pixel on a flat-shaded facet edge, where
an antialiased normal pass blends the facets and a pixel-centre sample does not."""


def _neighbour_differs(image: np.ndarray, differs) -> np.ndarray:
    """True where ``differs(pixel, neighbour)`` holds for any of the 8 neighbours (edges replicated)."""
    padded = np.pad(image, [(1, 1), (1, 1)] + [(0, 0)] * (image.ndim - 2), mode="edge")
    h, w = image.shape[:2]
    mask = np.zeros((h, w), dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                mask |= differs(image, padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w])
    return mask


def silhouette_edges(depth: np.ndarray, instances: np.ndarray | None = None) -> np.ndarray:
    """Pixels on a silhouette: a neighbour (8-connected) is background where this one is not (or the reverse),
    lies more than DEPTH_JUMP deeper or shallower (relative), or shows another instance."""
    depth = np.asarray(depth, dtype=np.float64)
    background = depth >= BACKGROUND_DEPTH
    finite = np.where(background, 0.0, depth)
    mask = _neighbour_differs(background, lambda a, b: a != b)
    mask |= _neighbour_differs(finite, lambda a, b: (np.abs(a - b) > DEPTH_JUMP * np.maximum(a, b)))
    if instances is not None:
        mask |= _neighbour_differs(np.asarray(instances), lambda a, b: a != b)
    return mask


def comparable(depth_a: np.ndarray, depth_b: np.ndarray, instances_a: np.ndarray | None = None,
               instances_b: np.ndarray | None = None) -> np.ndarray:
    """Pixels where both engines see a surface and neither puts a silhouette edge."""
    surface = (np.asarray(depth_a) < BACKGROUND_DEPTH) & (np.asarray(depth_b) < BACKGROUND_DEPTH)
    return surface & ~silhouette_edges(depth_a, instances_a) & ~silhouette_edges(depth_b, instances_b)


def crease_edges(*encoded_normals: np.ndarray) -> np.ndarray:
    """Pixels where, in any of the given normal images, a neighbour's normal is more than CREASE_DEGREES away."""
    limit = np.cos(np.radians(CREASE_DEGREES))
    mask = np.zeros(np.asarray(encoded_normals[0]).shape[:2], dtype=bool)
    for encoded in encoded_normals:
        mask |= _neighbour_differs(decode_normals(encoded), lambda a, b: np.sum(a * b, axis=-1) < limit)
    return mask


@dataclass(frozen=True)
class Agreement:
    """Absolute differences over the compared pixels: median, 99th percentile, the fraction within
    ``tolerance``, how many pixels were compared and the fraction of all pixels that is."""

    median: float
    p99: float
    within: float
    tolerance: float
    pixels: int
    coverage: float


def agreement(differences: np.ndarray, tolerance: float, total: int) -> Agreement:
    """Summary of absolute differences (any shape, e.g. several frames' concatenated) out of ``total`` pixels."""
    differences = np.asarray(differences, dtype=np.float64).ravel()
    if differences.size == 0:
        return Agreement(float("nan"), float("nan"), float("nan"), tolerance, 0, 0.0)
    return Agreement(float(np.median(differences)), float(np.percentile(differences, 99)),
                     float(np.mean(differences <= tolerance)), tolerance, int(differences.size),
                     differences.size / max(total, 1))


def depth_differences(ours: np.ndarray, theirs: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """|depth difference| (m) at the ``mask`` pixels."""
    return np.abs(np.asarray(ours, dtype=np.float64) - np.asarray(theirs, dtype=np.float64))[mask]


def decode_normals(encoded: np.ndarray) -> np.ndarray:
    """``0.5 n + 0.5`` -> unit vectors (float64, H x W x 3)."""
    n = 2.0 * np.asarray(encoded, dtype=np.float64)[..., :3] - 1.0
    return n / np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)


def normal_differences(ours: np.ndarray, theirs: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Angle between the two engines' normals (degrees) at the ``mask`` pixels."""
    cos = np.clip(np.sum(decode_normals(ours) * decode_normals(theirs), axis=-1), -1.0, 1.0)
    return np.degrees(np.arccos(cos))[mask]


@dataclass(frozen=True)
class IdMatch:
    """The one-to-one id mapping (ours -> theirs) that maximises the pixels on which the maps agree, and the
    fraction of ``mask`` pixels on which they agree under it."""

    mapping: dict[int, int]
    agreement: float
    pixels: int


def match_ids(ours: np.ndarray, theirs: np.ndarray, mask: np.ndarray | None = None) -> IdMatch:
    """Best permutation between two integer id maps (Hungarian assignment on the pixel-overlap table); ids
    without a partner map to -1."""
    ours, theirs = np.asarray(ours).ravel(), np.asarray(theirs).ravel()
    if mask is not None:
        keep = np.asarray(mask).ravel()
        ours, theirs = ours[keep], theirs[keep]
    if ours.size == 0:
        return IdMatch({}, float("nan"), 0)
    ids_a, inv_a = np.unique(ours, return_inverse=True)
    ids_b, inv_b = np.unique(theirs, return_inverse=True)
    overlap = np.zeros((ids_a.size, ids_b.size), dtype=np.int64)
    np.add.at(overlap, (inv_a, inv_b), 1)
    rows, cols = linear_sum_assignment(overlap, maximize=True)
    mapping = {int(a): -1 for a in ids_a}
    mapping.update({int(ids_a[r]): int(ids_b[c]) for r, c in zip(rows, cols) if overlap[r, c] > 0})
    agreed = int(sum(overlap[r, c] for r, c in zip(rows, cols)))
    return IdMatch(mapping, agreed / ours.size, int(ours.size))


def srgb_to_linear(colors: np.ndarray) -> np.ndarray:
    """uint8 sRGB -> linear float64 in [0, 1] (hybridgen's sRGB decoding)."""
    return srgb_decode(np.asarray(colors, dtype=np.float64)[..., :3] / 255.0)


def mean_color_per_id(colors: np.ndarray, ids: np.ndarray, mask: np.ndarray | None = None) -> dict[int, np.ndarray]:
    """Mean linear RGB of every id's pixels (within ``mask``)."""
    linear = srgb_to_linear(colors).reshape(-1, 3)
    ids = np.asarray(ids).ravel()
    keep = np.ones(ids.shape, dtype=bool) if mask is None else np.asarray(mask).ravel()
    return {int(i): linear[keep & (ids == i)].mean(axis=0) for i in np.unique(ids[keep])}


def luminance(rgb: np.ndarray) -> float:
    """Rec. 709 luminance of a linear RGB triple."""
    return float(np.dot(np.asarray(rgb, dtype=np.float64), (0.2126, 0.7152, 0.0722)))


def pose_difference(ours: np.ndarray, theirs: np.ndarray) -> tuple[float, float]:
    """(translation distance in m, rotation angle in degrees) between two 4x4 rigid transforms."""
    ours, theirs = np.asarray(ours, dtype=np.float64), np.asarray(theirs, dtype=np.float64)
    chord = np.linalg.norm(ours[:3, :3] - theirs[:3, :3])  # = 2 sqrt(2) sin(angle / 2), exact near 0 (arccos is not)
    angle = np.degrees(2.0 * np.arcsin(min(chord / (2.0 * np.sqrt(2.0)), 1.0)))
    return float(np.linalg.norm(ours[:3, 3] - theirs[:3, 3])), float(angle)

