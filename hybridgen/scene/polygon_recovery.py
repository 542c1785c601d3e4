"""The polygons behind a loader's triangles: which neighbouring triangles were one quad or n-gon of the file.

Blender keeps a file's quads and n-gons; hybridgen's loaders triangulate them (quads along a diagonal, n-gons as
fans). Modifiers whose result depends on the polygons - Catmull-Clark subdivision above all - need them back. A
polygon's triangles are coplanar, share edges, and (as the loaders triangulate) all meet at one corner with no
vertex inside. So, over the welded mesh:

1. Triangles are linked across an edge shared by exactly two of them, wound oppositely (consistent), of the same
   part (material) and coplanar (normals within 1e-5 rad).
2. A linked group of two is a quad. A larger group whose triangles all share one vertex and whose outline is one
   loop through all its k + 2 vertices is one polygon (a fan: a cylinder's cap).
3. Any other group (a flat grid of quads) is paired into quads: two triangles whose shared edge is the longest
   edge of both (a quad's diagonal), first come first paired; the rest stay triangles.

What cannot be told apart: two coplanar triangles that were two triangles in the file become a quad; a 2 x 1
strip of quads whose diagonals meet at one vertex becomes a hexagon. Callers skip the recovery for files known to
hold only triangles.
"""
from __future__ import annotations

import numpy as np

COPLANAR_COS = 1.0 - 5e-11
"""Two triangles are coplanar when their unit normals' dot product exceeds this (about 1e-5 rad)."""


def _links(positions: np.ndarray, triangles: np.ndarray, part: np.ndarray) -> np.ndarray:
    """(K, 2, 2) pairs of linked triangles: [[t1, corner of t1 starting the shared edge], [t2, its corner]]."""
    corners = positions[triangles]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    start, end = triangles.ravel(), triangles[:, [1, 2, 0]].ravel()
    key = np.sort(np.stack([start, end], axis=1), axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    shared = np.flatnonzero(counts[inverse] == 2)
    order = shared[np.argsort(inverse[shared], kind="stable")]
    first, second = order[0::2], order[1::2]
    t1, t2 = first // 3, second // 3
    keep = ((start[first] == end[second]) & (part[t1] == part[t2]) & (t1 != t2)
            & (np.einsum("ij,ij->i", normals[t1], normals[t2]) > COPLANAR_COS))
    return np.stack([np.stack([t1, first % 3], 1), np.stack([t2, second % 3], 1)], axis=1)[keep]


def _quad(triangles: np.ndarray, a: np.ndarray, b: np.ndarray) -> list[int]:
    """Corner ids (triangle * 3 + k) of the quad of two triangles sharing the edge that starts at corner ``a[1]``
    of triangle ``a[0]`` (and at ``b[1]`` of ``b[0]`` in the other direction)."""
    t1, k1 = int(a[0]), int(a[1])
    t2, k2 = int(b[0]), int(b[1])
    return [3 * t1 + k1, 3 * t2 + (k2 + 2) % 3, 3 * t1 + (k1 + 1) % 3, 3 * t1 + (k1 + 2) % 3]


def _fan(triangles: np.ndarray, members: np.ndarray) -> list[int] | None:
    """The outline of a group of triangles as corner ids when it is one fan polygon (module doc), else None."""
    vertices = triangles[members]
    if not set.intersection(*(set(row) for row in vertices.tolist())) or len(np.unique(vertices)) != len(members) + 2:
        return None
    directed = {(int(u), int(v)) for row in vertices for u, v in zip(row, np.roll(row, -1))}
    outline = {u: v for u, v in directed if (v, u) not in directed}
    if len(outline) != len(members) + 2:
        return None
    corner_of = {int(v): 3 * int(t) + k for t, row in zip(members, vertices) for k, v in enumerate(row)}
    loop, vertex = [], next(iter(outline))
    for _ in range(len(outline)):
        loop.append(corner_of[vertex])
        vertex = outline.get(vertex, -1)
        if vertex < 0:
            return None
    closed = vertex == triangles.ravel()[loop[0]] and len(set(loop)) == len(loop)
    return loop if closed else None


def _pairs(positions: np.ndarray, triangles: np.ndarray, links: np.ndarray) -> list[list[int]]:
    """Quads of linked triangles whose shared edge is the longest edge of both (first come first paired)."""
    corners = positions[triangles]
    lengths = np.linalg.norm(corners[:, [1, 2, 0]] - corners, axis=2)  # edge k starts at corner k
    used: set[int] = set()
    quads = []
    for a, b in links:
        t1, t2 = int(a[0]), int(b[0])
        if t1 in used or t2 in used:
            continue
        longest = lengths[t1].max() * (1 - 1e-12), lengths[t2].max() * (1 - 1e-12)
        if lengths[t1, a[1]] >= longest[0] and lengths[t2, b[1]] >= longest[1]:
            quads.append(_quad(triangles, a, b))
            used.update((t1, t2))
    return quads


def recover_polygons(positions: np.ndarray, triangles: np.ndarray, part: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polygons of the welded ``triangles`` (T, 3) over ``positions``: (corner ids - triangle * 3 + corner - of
    every polygon's loop in winding order, concatenated; (P + 1,) loop starts). Polygons follow their first
    triangle's order."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    count = len(triangles)
    links = _links(positions, triangles, part)
    graph = coo_matrix((np.ones(len(links)), (links[:, 0, 0], links[:, 1, 0])), shape=(count, count))
    _, label = connected_components(graph, directed=False)
    sizes = np.bincount(label, minlength=count)
    loops: dict[int, list[int]] = {}
    merged = np.zeros(count, dtype=bool)
    two = links[sizes[label[links[:, 0, 0]]] == 2]
    for a, b in two:
        loops[int(min(a[0], b[0]))] = _quad(triangles, a, b)
        merged[[a[0], b[0]]] = True
    for group in np.flatnonzero(sizes > 2):
        members = np.flatnonzero(label == group)
        fan = _fan(triangles, members)
        if fan is not None:
            loops[int(members[0])] = fan
            merged[members] = True
            continue
        inside = links[np.isin(links[:, 0, 0], members)]
        for quad in _pairs(positions, triangles, inside):
            loops[min(quad[0], quad[1]) // 3] = quad
            merged[[quad[0] // 3, quad[1] // 3]] = True
    for t in np.flatnonzero(~merged):
        loops[int(t)] = [3 * int(t), 3 * int(t) + 1, 3 * int(t) + 2]
    ordered = [loops[key] for key in sorted(loops)]
    starts = np.concatenate([[0], np.cumsum([len(loop) for loop in ordered])]).astype(np.int64)
    return np.array([c for loop in ordered for c in loop], dtype=np.int64), starts
