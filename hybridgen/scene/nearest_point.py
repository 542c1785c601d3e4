"""The point of a triangle nearest to a query point (Ericson, "Real-Time Collision Detection", 5.1.5), for many
triangles at once: the query's Voronoi region of the triangle (a vertex, an edge or the face) picks the point."""
from __future__ import annotations

import numpy as np


def closest_points(point: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(N, 3) the point of each triangle ``(a[i], b[i], c[i])`` (N x 3 each) nearest to ``point`` (3,); a degenerate
    triangle gives one of its nearest points too."""
    p = np.asarray(point, dtype=np.float64)[None]
    ab, ac, ap = b - a, c - a, p - a
    bp, cp = p - b, p - c

    def dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.einsum("ij,ij->i", u, v)

    d1, d2 = dot(ab, ap), dot(ac, ap)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        on_ab = a + np.nan_to_num(d1 / (d1 - d3))[:, None] * ab
        on_ac = a + np.nan_to_num(d2 / (d2 - d6))[:, None] * ac
        on_bc = b + np.nan_to_num((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None] * (c - b)
        total = va + vb + vc
        inside = a + np.nan_to_num(vb / total)[:, None] * ab + np.nan_to_num(vc / total)[:, None] * ac
    regions = [(d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (vc <= 0) & (d1 >= 0) & (d3 <= 0),
               (d6 >= 0) & (d5 <= d6), (vb <= 0) & (d2 >= 0) & (d6 <= 0),
               (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)]
    choices = [a, b, on_ab, c, on_ac, on_bc]
    return np.select([r[:, None] for r in regions], choices, default=inside)
