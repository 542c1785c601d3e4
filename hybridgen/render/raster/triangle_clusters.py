"""Per-keypoint culling of triangle clusters that cannot produce a fragment (llvmpipe shades every vertex it
is given, on the thread that issues the draws: for a 1.4M-triangle mesh that is most of a keypoint's time).

At upload an object's triangles are cut into clusters of :data:`CLUSTER_TRIANGLES` consecutive triangles **in
their original order** - never reordered, so what is drawn is the original sequence with some triangles left
out, and a label can only change if a left-out triangle would have covered a pixel centre. Per keypoint a
cluster is left out when, in exact arithmetic with a margin far above float32 rounding, either

* its bounding box lies wholly outside one side of the view frustum: left of the image's left edge
  (u < -0.5 px), right of its right edge, above, below (pixel centres lie 0.5 px inside those edges), nearer
  than the near plane or beyond the far plane; or
* the object is drawn with back faces culled (closed, outward wound, camera outside it: raster.py) and every
  triangle of the cluster faces away from the camera: ``n_i . (c - p_i) < 0`` for each triangle's winding
  normal ``n_i``, vertex ``p_i`` and camera centre ``c`` (object-local coordinates; the sign is invariant under
  the object's affine transform). The bound used: with unit normals ``n_i = a + e_i``, ``|e_i| <= spread`` and
  ``reach = max_i -n_i . (p_i - o)`` about the box centre ``o``, ``n_i . (c - p_i) <= a . (c - o) +
  spread |c - o| + reach``. Clusters holding a degenerate triangle are never culled this way.

The kept clusters are drawn with one ``glMultiDrawElementsIndirect`` per object (runs of consecutive kept
clusters merged), so culling costs no extra draw calls.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CLUSTER_TRIANGLES = 512
"""Triangles per cluster (the last one of an object may hold fewer)."""
MIN_TRIANGLES = 4 * CLUSTER_TRIANGLES
"""Objects with fewer triangles are not clustered (drawn whole)."""
FACING_MARGIN = 1e-4
"""Relative margin of the back-facing test (times the distance scale): a float32 transform errs ~1e-7."""
NEAR_FAR_MARGIN = 1e-4
"""Relative margin of the near/far plane tests."""


@dataclass
class TriangleClusters:
    """Culling data of one object's clusters (object-local, float64): boxes, normal cones, triangle ranges."""

    first: np.ndarray  # (K,) first triangle of each cluster
    count: np.ndarray  # (K,) triangles in each cluster
    corners: np.ndarray  # (K, 8, 3) bounding box corners
    centre: np.ndarray  # (K, 3) box centres o
    axis: np.ndarray  # (K, 3) unit cone axis a
    spread: np.ndarray  # (K,) max |n_i - a|
    reach: np.ndarray  # (K,) max -n_i . (p_i - o)
    facing_ok: np.ndarray  # (K,) bool: no degenerate triangle (the back-facing test applies)
    scale: np.ndarray  # (K,) box half-diagonal (margin scale)

    @property
    def size(self) -> int:
        return len(self.first)


def build_clusters(vertices: np.ndarray, faces: np.ndarray) -> TriangleClusters | None:
    """The clusters of a mesh (``vertices`` (N, 3), ``faces`` (M, 3) as uploaded, in drawing order); None for
    a mesh of fewer than :data:`MIN_TRIANGLES` triangles."""
    m = len(faces)
    if m < MIN_TRIANGLES:
        return None
    size = CLUSTER_TRIANGLES
    first = np.arange(0, m, size)
    count = np.minimum(size, m - first)
    k = len(first)
    corners = np.zeros((k, 8, 3))
    centre, axis = np.zeros((k, 3)), np.zeros((k, 3))
    spread, reach, scale = np.zeros(k), np.zeros(k), np.zeros(k)
    facing_ok = np.zeros(k, dtype=bool)
    verts = np.asarray(vertices, dtype=np.float64)
    grid = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
    step = max(1, 262_144 // size)  # clusters per batch: bounded temporary memory
    for start in range(0, k, step):
        stop = min(k, start + step)
        tri_start = int(first[start])
        tri = verts[faces[tri_start:int(first[stop - 1] + count[stop - 1])]]  # (T, 3, 3)
        offsets = first[start:stop] - tri_start  # each cluster's first triangle in the batch
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        length = np.linalg.norm(n, axis=1)
        degenerate = ~(length > 0)
        unit = n / np.where(degenerate, 1.0, length)[:, None]
        owner = np.repeat(np.arange(stop - start), count[start:stop])
        p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]
        low = np.minimum.reduceat(np.minimum(np.minimum(p0, p1), p2), offsets)
        high = np.maximum.reduceat(np.maximum(np.maximum(p0, p1), p2), offsets)
        o = (low + high) / 2
        summed = np.add.reduceat(unit, offsets)
        norm = np.linalg.norm(summed, axis=1)
        a = summed / np.where(norm > 0, norm, 1.0)[:, None]
        spread_b = np.maximum.reduceat(np.linalg.norm(unit - a[owner], axis=1), offsets)
        # -n_i . (p_i - o): the plane of triangle i through any of its vertices; the largest over its vertices
        centres = o[owner]
        per_triangle = np.maximum(np.maximum(-np.einsum("ij,ij->i", unit, p0 - centres),
                                             -np.einsum("ij,ij->i", unit, p1 - centres)),
                                  -np.einsum("ij,ij->i", unit, p2 - centres))
        reach_b = np.maximum.reduceat(per_triangle, offsets)
        bad = np.logical_or.reduceat(degenerate, offsets)
        sel = slice(start, stop)
        corners[sel] = low[:, None, :] + grid[None] * (high - low)[:, None, :]
        centre[sel], axis[sel], spread[sel], reach[sel] = o, a, spread_b, reach_b
        facing_ok[sel] = ~bad & (norm > 0)
        scale[sel] = np.linalg.norm(high - low, axis=1) / 2
    return TriangleClusters(first, count, corners, centre, axis, spread, reach, facing_ok, scale)


def visible_clusters(clusters: TriangleClusters, modelview: np.ndarray, K: np.ndarray, width: int, height: int,
                     near: float, far: float, cam_local: np.ndarray | None) -> np.ndarray:
    """(K,) bool: the clusters that may produce a fragment at this keypoint. ``modelview``: 4x4 object-local ->
    OpenCV camera (float64); ``cam_local``: the camera centre in object-local coordinates when the object is
    drawn with back faces culled, else None."""
    cam = clusters.corners @ modelview[:3, :3].T + modelview[:3, 3]  # (K, 8, 3)
    x, y, z = cam[..., 0], cam[..., 1], cam[..., 2]
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    outside = ((fx * x + (cx + 0.5) * z < 0).all(axis=1)  # u < -0.5 px for every corner (z > 0 or not)
               | (fx * x + (cx + 0.5 - width) * z > 0).all(axis=1)  # u > width - 0.5
               | (fy * y + (cy + 0.5) * z < 0).all(axis=1)
               | (fy * y + (cy + 0.5 - height) * z > 0).all(axis=1)
               | (z < near * (1 - NEAR_FAR_MARGIN)).all(axis=1)
               | (z > far * (1 + NEAR_FAR_MARGIN)).all(axis=1))
    keep = ~outside
    if cam_local is not None:
        offset = np.asarray(cam_local, dtype=np.float64)[None, :] - clusters.centre  # c - o
        distance = np.linalg.norm(offset, axis=1)
        bound = np.einsum("ij,ij->i", clusters.axis, offset) + clusters.spread * distance + clusters.reach
        back = clusters.facing_ok & (bound < -FACING_MARGIN * (distance + clusters.scale))
        keep &= ~back
    return keep


def draw_commands(clusters: TriangleClusters, keep: np.ndarray) -> np.ndarray:
    """(R, 5) uint32 ``DrawElementsIndirectCommand`` rows (count, instances, first index, base vertex, base
    instance) drawing the kept clusters, consecutive ones merged into one run, in the original order. The base
    instance is the run's first triangle: the exact-depth label shader adds it to ``gl_PrimitiveID``, which
    restarts at 0 in every command of a multi-draw (render/raster/face_planes.py)."""
    if not keep.any():
        return np.zeros((0, 5), dtype=np.uint32)
    edges = np.diff(np.concatenate([[0], keep.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    first = clusters.first[starts]
    last = clusters.first[stops] + clusters.count[stops]
    out = np.zeros((len(starts), 5), dtype=np.uint32)
    out[:, 0] = 3 * (last - first)
    out[:, 1] = 1
    out[:, 2] = 3 * first
    out[:, 4] = first
    return out
