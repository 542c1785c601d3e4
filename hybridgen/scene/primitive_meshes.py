"""Triangle meshes of the analytic primitives, built with NumPy alone (no trimesh import).

Each builder returns ``(vertices, faces)``: (V, 3) float64 positions in metres in the shape's local frame
(centred on the origin, Z up) and (F, 3) int64 vertex indices wound counter-clockwise seen from outside.
They are the arrays ``trimesh.creation`` (5.x) makes for the same arguments, bit for bit - same vertex order,
face order and winding, and the same floating-point operations in the same order - so scenes render exactly
as they did when trimesh built them, while a run that only builds primitives skips trimesh's import
(~0.4 s CPU per process). ``tests/scene/test_primitive_meshes.py`` holds them against trimesh.
"""
from __future__ import annotations

import numpy as np

from .closed_volume import merged_vertices

Mesh = tuple[np.ndarray, np.ndarray]
"""(V, 3) float64 vertices (m) and (F, 3) int64 faces."""

_UNIT_CUBE_VERTICES = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1],
                                [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]], dtype=np.float64)
_CUBE_FACES = np.array([[1, 3, 0], [4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4],
                        [5, 7, 1], [3, 7, 2], [6, 4, 2], [2, 7, 6], [6, 5, 4], [7, 5, 6]], dtype=np.int64)

_ICO_A, _ICO_B = 0.5257311121191336, 0.85065080835204
"""The unit icosahedron's coordinates (1, phi) / |(1, phi)|, as the decimals trimesh stores them."""
_ICOSAHEDRON_VERTICES = np.array([
    [-_ICO_A, _ICO_B, 0.0], [_ICO_A, _ICO_B, 0.0], [-_ICO_A, -_ICO_B, 0.0], [_ICO_A, -_ICO_B, 0.0],
    [0.0, -_ICO_A, _ICO_B], [0.0, _ICO_A, _ICO_B], [0.0, -_ICO_A, -_ICO_B], [0.0, _ICO_A, -_ICO_B],
    [_ICO_B, 0.0, -_ICO_A], [_ICO_B, 0.0, _ICO_A], [-_ICO_B, 0.0, -_ICO_A], [-_ICO_B, 0.0, _ICO_A]],
    dtype=np.float64)
_ICOSAHEDRON_FACES = np.array([
    [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6],
    [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
    [8, 6, 7], [9, 8, 1]], dtype=np.int64)


def box(extents: tuple[float, float, float]) -> Mesh:
    """An axis-aligned box with edge lengths ``extents`` (m) centred on the origin: 8 vertices, 12 faces."""
    vertices = _UNIT_CUBE_VERTICES.copy()
    vertices -= 0.5
    vertices *= np.asarray(extents, dtype=np.float64)
    return vertices, _CUBE_FACES.copy()


def plane(size: float) -> Mesh:
    """A ``size`` x ``size`` square (m) in the local XY plane, facing +Z: 4 vertices, 2 faces."""
    corners = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64)
    return corners * size / 2, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)


def icosphere(subdivisions: int, radius: float) -> Mesh:
    """A sphere of ``radius`` (m): the icosahedron, each triangle split into four ``subdivisions`` times with
    every vertex pushed back onto the sphere after each split (12 + 10 (4^n - 1) vertices, 20 4^n faces)."""
    vertices, faces = _ICOSAHEDRON_VERTICES.copy(), _ICOSAHEDRON_FACES.copy()
    for _ in range(subdivisions):
        vertices, faces = _subdivided(vertices, faces)
        vertices = _onto_sphere(vertices, radius)
    if subdivisions <= 0:
        vertices = _onto_sphere(vertices, radius)
    return vertices, faces


def _subdivided(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    """Every face split into four at its edge midpoints. Midpoints are appended after ``vertices``, one per
    undirected edge, ordered by (larger index, smaller index); each face becomes (corner 0, mid 01, mid 20),
    (mid 01, corner 1, mid 12), (mid 20, mid 12, corner 2), (mid 01, mid 12, mid 20)."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    key = (edges[:, 1] << 32) | edges[:, 0]
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    mid = vertices[edges[first]].mean(axis=1)
    mid_index = inverse.reshape(-1, 3) + len(vertices)
    split = np.column_stack([
        faces[:, 0], mid_index[:, 0], mid_index[:, 2],
        mid_index[:, 0], faces[:, 1], mid_index[:, 1],
        mid_index[:, 2], mid_index[:, 1], faces[:, 2],
        mid_index[:, 0], mid_index[:, 1], mid_index[:, 2]]).reshape(-1, 3)
    return np.vstack((vertices, mid)), split


def _onto_sphere(vertices: np.ndarray, radius: float) -> np.ndarray:
    """``vertices`` moved along their direction from the origin to distance ``radius`` (m)."""
    distance = np.sqrt(np.dot(vertices ** 2, [1, 1, 1]))
    unit = vertices / distance.reshape((-1, 1))
    moved = vertices.copy()
    moved += unit * (radius - distance).reshape((-1, 1))
    return moved


def cylinder(radius: float, height: float, sections: int) -> Mesh:
    """A closed cylinder around Z of ``radius`` and ``height`` (m), centred on the origin, its side split
    into ``sections`` wedges (caps are fans around one centre vertex each)."""
    half = abs(float(height)) / 2.0
    return revolve(np.array([[0, -half], [radius, -half], [radius, half], [0, half]], dtype=np.float64),
                   sections)


def cone(radius: float, height: float, sections: int) -> Mesh:
    """A closed cone around Z: base disc of ``radius`` (m) at z = 0, apex at z = ``height`` (m)."""
    return revolve(np.array([[0, 0], [radius, 0], [0, height]], dtype=np.float64), sections)


def torus(major_radius: float, minor_radius: float, major_sections: int = 32, minor_sections: int = 32) -> Mesh:
    """A torus around Z centred on the origin: a tube of ``minor_radius`` (m) whose centre circle has
    ``major_radius`` (m), with ``major_sections`` x ``minor_sections`` quads (two triangles each)."""
    phi = np.linspace(0, 2 * np.pi, minor_sections + 1, endpoint=True)
    profile = np.column_stack((minor_radius * np.cos(phi), minor_radius * np.sin(phi))) + [major_radius, 0]
    return revolve(profile, major_sections)


def revolve(profile: np.ndarray, sections: int) -> Mesh:
    """A closed surface of revolution: the (P, 2) ``profile`` (radius, z) in metres, swept once around Z in
    ``sections`` equal steps. Vertex ``s * P + p`` is profile point ``p`` at angle ``2 pi s / sections``;
    each step between profile points ``p`` and ``p + 1`` gives the triangles (p, p + P, p + 1) and
    (p + 1, p + P, p + P + 1) of every section, less those of zero area (points on the axis); then
    coincident vertices (the axis points, a closed profile's ends) are merged, keeping first occurrences.

    trimesh drops triangles of area <= 1e-8 m^2 instead of exactly zero: the same faces for primitives above
    ~2 cm, while it leaves a torus of 1 mm with no faces at all; here every non-degenerate face stays."""
    theta = np.linspace(0, np.pi * 2.0, sections + 1)
    ring = np.column_stack((np.cos(theta), np.sin(theta)))
    per = len(profile)
    radius, height = profile[:, 0], profile[:, 1]
    vertices = np.column_stack((np.tile(ring, (1, per)).reshape((-1, 2)) * np.tile(radius, len(ring)).reshape((-1, 1)),
                                np.tile(height, len(ring))))[:-per]  # the last ring repeats the first
    quad = np.array([0, per, 1, 1, per, per + 1])
    single = np.tile(quad, per - 1).reshape((-1, 3))
    single += np.tile(np.arange(per - 1), (2, 1)).T.reshape((-1, 1))
    single = single[_triangle_areas(vertices[single]) > 0.0]  # two corners on the axis: exactly zero
    offset = np.tile(np.arange(sections) * per, (len(single), 1)).T.reshape((-1, 1))
    faces = (np.tile(single.ravel(), sections).reshape((-1, 3)) + offset) % len(vertices)
    merged_faces, representative = merged_vertices(vertices, faces)
    return vertices[representative], merged_faces


def _triangle_areas(triangles: np.ndarray) -> np.ndarray:
    """Areas (m^2) of (F, 3, 3) ``triangles``."""
    edges = triangles[:, 1:, :] - triangles[:, :2, :]
    return np.linalg.norm(np.cross(edges[:, 0], edges[:, 1]), axis=1) / 2.0
