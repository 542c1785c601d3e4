"""Catmull-Clark subdivision of a polygon mesh as Blender's Subdivision Surface modifier evaluates it with its
defaults (``subdivision_type`` CATMULL_CLARK, ``boundary_smooth`` ALL, ``use_limit_surface`` on, no creases).

One level: every polygon of n corners becomes n quads (corner, edge point, face point, edge point). Face point:
the mean of the polygon's corners. Edge point: the mean of the edge's ends and its two face points; on a boundary
(an edge of one polygon - or of three and more, non-manifold) the edge's midpoint. Vertex point of an interior
vertex of valence n: (Q + 2 R + (n - 3) V) / n, Q the mean of the face points around it, R the mean of its edges'
midpoints; of a vertex on exactly two boundary edges (corners too: "All" smooths them) (A + 6 V + B) / 8 from the
two boundary neighbours; any other vertex stays. After the last level every vertex moves to its limit position:
interior (n^2 V + 4 sum(edge neighbours) + sum(diagonal neighbours)) / (n (n + 5)), boundary (A + 4 V + B) / 6 -
except a boundary vertex of valence 2 (a lone quad's corner), where Blender (OpenSubdiv, which refines such an
irregular vertex ``quality`` = 3 times and takes that point) keeps the point of the third level: with the B-spline
boundary's contraction of 1/4 per level, L + 4^(levels - 3) (V - L), L its limit (measured with bpy 4.2 on a lone
quad at levels 1-4: 43/64 of the way out where the limit is 2/3, the other vertices at their limits up to level 3).

Per-corner attributes (UVs, normals, colors) are subdivided linearly inside each polygon (Blender's ``uv_smooth``
NONE; its default PRESERVE_BOUNDARIES also smooths UVs inside UV islands). Measured against bpy 4.2 (a 2 m cube:
face centres at 0.8395 m, corners at (0.5, 0.5, 0.5) m at every level; tests/scene/test_catmull_clark.py).
"""
from __future__ import annotations

import numpy as np

from .polygon_mesh import PolygonMesh


def _edges(mesh: PolygonMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique undirected edges (E, 2), the edge of each corner (corner -> next corner), polygons per edge (E,)."""
    nxt = mesh.next_corner()
    pairs = np.sort(np.stack([mesh.corners, mesh.corners[nxt]], axis=1), axis=1)
    edges, edge_of_corner, counts = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
    return edges, edge_of_corner.reshape(-1), counts


def _partner_sum(positions: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Per vertex, the sum of the positions at the other end of each of ``edges`` touching it."""
    out = np.zeros_like(positions)
    np.add.at(out, edges[:, 0], positions[edges[:, 1]])
    np.add.at(out, edges[:, 1], positions[edges[:, 0]])
    return out


def _kinds(mesh: PolygonMesh, edges: np.ndarray, boundary: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per vertex: valence (float), interior mask (valence >= 3, no boundary edge, in a polygon), crease mask
    (exactly two boundary edges)."""
    count = len(mesh.positions)
    valence = np.bincount(edges.ravel(), minlength=count).astype(np.float64)
    on_boundary = np.bincount(edges[boundary].ravel(), minlength=count)
    in_polygon = np.bincount(mesh.corners, minlength=count) > 0
    return valence, (on_boundary == 0) & in_polygon & (valence >= 3), on_boundary == 2


def _vertex_points(mesh: PolygonMesh, edges: np.ndarray, boundary: np.ndarray, faces: np.ndarray) -> np.ndarray:
    p = mesh.positions
    valence, interior, crease = _kinds(mesh, edges, boundary)
    corners_at = np.bincount(mesh.corners, minlength=len(p)).astype(np.float64)
    face_sum = np.zeros_like(p)
    np.add.at(face_sum, mesh.corners, faces[mesh.polygon_of_corner()])
    out = p.copy()
    n = valence[interior][:, None]
    q = face_sum[interior] / corners_at[interior][:, None]
    r = 0.5 * (p[interior] + _partner_sum(p, edges)[interior] / n)  # mean of the edge midpoints
    out[interior] = (q + 2.0 * r + (n - 3.0) * p[interior]) / n
    out[crease] = (_partner_sum(p, edges[boundary])[crease] + 6.0 * p[crease]) / 8.0
    return out


def _step(mesh: PolygonMesh, smooth: bool = True) -> PolygonMesh:
    """One Catmull-Clark level (module doc); not ``smooth``: Blender's SIMPLE subdivision (edge midpoints, face
    centres, vertices kept)."""
    p, corners = mesh.positions, mesh.corners
    polygon = mesh.polygon_of_corner()
    sizes = mesh.sizes.astype(np.float64)
    faces = np.zeros((len(sizes), 3))
    np.add.at(faces, polygon, p[corners])
    faces /= sizes[:, None]
    edges, edge_of_corner, counts = _edges(mesh)
    boundary = counts != 2
    face_sum = np.zeros((len(edges), 3))
    np.add.at(face_sum, edge_of_corner, faces[polygon])
    midpoints = 0.5 * (p[edges[:, 0]] + p[edges[:, 1]])
    if smooth:
        edge_points = np.where(boundary[:, None], midpoints, 0.5 * midpoints + 0.25 * face_sum)
        vertex_points = _vertex_points(mesh, edges, boundary, faces)
    else:
        edge_points, vertex_points = midpoints, p
    base_edge, base_face = len(p), len(p) + len(edges)
    nxt, prv = mesh.next_corner(), mesh.previous_corner()
    quads = np.stack([corners, base_edge + edge_of_corner, base_face + polygon, base_edge + edge_of_corner[prv]], 1)
    attributes = {}
    for name, values in mesh.attributes.items():
        mean = np.zeros((len(sizes), values.shape[1]))
        np.add.at(mean, polygon, values)
        mean /= sizes[:, None]
        attributes[name] = np.stack([values, 0.5 * (values + values[nxt]), mean[polygon],
                                     0.5 * (values + values[prv])], axis=1).reshape(-1, values.shape[1])
    return PolygonMesh(np.concatenate([vertex_points, edge_points, faces]), quads.reshape(-1),
                       np.arange(0, 4 * len(corners) + 1, 4), mesh.part[polygon], attributes)


QUALITY = 3
"""Blender's Subdivision Surface ``quality`` (its default): how often OpenSubdiv refines an irregular vertex."""


def limit_positions(mesh: PolygonMesh, levels: int = QUALITY) -> np.ndarray:
    """The limit positions (V, 3) of a quad mesh's vertices after ``levels`` levels (module doc)."""
    p = mesh.positions
    edges, _, counts = _edges(mesh)
    boundary = counts != 2
    valence, interior, crease = _kinds(mesh, edges, boundary)
    diagonal = np.zeros_like(p)
    np.add.at(diagonal, mesh.corners, p[mesh.corners[mesh.next_corner()[mesh.next_corner()]]])
    out = p.copy()
    n = valence[interior][:, None]
    out[interior] = (n * n * p[interior] + 4.0 * _partner_sum(p, edges)[interior] + diagonal[interior]) / (n * (n + 5))
    out[crease] = (_partner_sum(p, edges[boundary])[crease] + 4.0 * p[crease]) / 6.0
    lone = crease & (valence == 2)  # Blender keeps the point of its QUALITY-th level there (module doc)
    out[lone] += 4.0 ** (levels - QUALITY) * (p[lone] - out[lone])
    return out


def subdivide(mesh: PolygonMesh, levels: int, limit: bool = True, smooth: bool = True) -> PolygonMesh:
    """``mesh`` after ``levels`` Catmull-Clark levels (``smooth`` False: SIMPLE subdivision), its vertices on the
    limit surface when ``limit`` (Blender's ``use_limit_surface``); ``levels`` 0 returns the mesh unchanged."""
    if levels <= 0:
        return mesh
    for _ in range(int(levels)):
        mesh = _step(mesh, smooth)
    if limit:
        mesh.positions = limit_positions(mesh, int(levels))
    return mesh
