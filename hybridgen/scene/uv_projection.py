"""Texture coordinates by projection, as Blender's UV operators make them when nothing but the mesh is given
(``bpy.ops.uv.cube_project()``, ``cylinder_project()``, ``sphere_project()`` on all faces, run without a 3D view
as BlenderProc runs them; measured against Blender 4.2).

All projections work per face corner (a vertex shared by faces may get other coordinates in each, so a mesh's
vertices are split per face corner). Coordinates: the mesh's local frame (metres); ``local2world`` is the object's
pose, whose rotation and scale the cylinder and sphere projections follow.

- cube: each face is projected along the local axis its normal is most aligned with (z first, then y, then x, on
  ties), onto the other two axes in (x, y) / (x, z) / (y, z) order: ``uv = 0.5 + (p - c) / size`` with ``c`` the
  centre of the vertices' bounding box and ``size`` its longest side.
- cylinder / sphere: ``q = A (p - c)`` with ``A = Rx(-90 deg) diag(-1, -1, 1) L`` (``L`` the pose's 3x3) puts the
  cylinder axis along q's z; cylinder ``u = (1 - atan2(qx, qy) / pi) / 2``, ``v = (qz + 1) / 2``; sphere the same
  ``u`` and ``v = 1 - acos(qz / |q|) / pi``. Across the seam (u = 0 / 1): of a face's corners, those within a
  half of its rightmost ``u`` set a left bound, and corners more than a half left of that bound move right by one;
  corners on the axis then take the mean ``u`` of the face's other corners. Blender decides this per polygon,
  hybridgen per triangle: a quad crossing the seam may have one triangle one unit apart (the same texel of a
  repeating texture).
"""
from __future__ import annotations

import numpy as np

PROJECTIONS = ("cube", "cylinder", "sphere")
_TO_POLAR = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]) @ np.diag([-1.0, -1.0, 1.0])


def _bounds_centre(vertices: np.ndarray) -> np.ndarray:
    return (vertices.min(axis=0) + vertices.max(axis=0)) / 2


def cube_uvs(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3, 2) per-corner coordinates of Blender's cube projection (see the module doc)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    tri = vertices[faces]
    normal = np.abs(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
    axes = np.where((normal[:, 2] >= normal[:, 0]) & (normal[:, 2] >= normal[:, 1]), 2,
                    np.where((normal[:, 1] >= normal[:, 0]) & (normal[:, 1] >= normal[:, 2]), 1, 0))
    pairs = np.array([[1, 2], [0, 2], [0, 1]])[axes]  # the two axes kept per face
    size = float(np.ptp(vertices, axis=0).max()) or 1.0
    local = (tri - _bounds_centre(vertices)) / size + 0.5
    return np.take_along_axis(local, np.repeat(pairs[:, None, :], 3, axis=1), axis=2)


def _polar_uvs(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray, sphere: bool) -> np.ndarray:
    vertices = np.asarray(vertices, dtype=np.float64)
    q = (vertices - _bounds_centre(vertices)) @ (_TO_POLAR @ np.asarray(local2world)[:3, :3]).T
    on_axis = np.hypot(q[:, 0], q[:, 1]) == 0
    u = np.where(on_axis, 0.0, (1 - np.arctan2(q[:, 0], q[:, 1]) / np.pi) / 2)
    if sphere:
        length = np.linalg.norm(q, axis=1)
        v = 1 - np.arccos(np.clip(q[:, 2] / np.where(length > 0, length, 1), -1, 1)) / np.pi
    else:
        v = (q[:, 2] + 1) / 2
    corner_u, corner_axis = u[faces], on_axis[faces]
    corner_u = np.where(corner_u >= 1, corner_u - 1, corner_u)
    right = corner_u.max(axis=1, keepdims=True)
    left = np.where(right <= corner_u + 0.5, corner_u, np.inf).min(axis=1, keepdims=True)
    corner_u = np.where(corner_u + 0.5 < left, corner_u + 1, corner_u)
    regular = (~corner_axis).sum(axis=1, keepdims=True)
    mean_u = np.where(corner_axis, 0.0, corner_u).sum(axis=1, keepdims=True) / np.maximum(regular, 1)
    corner_u = np.where(corner_axis, mean_u, corner_u)
    return np.stack([corner_u, v[faces]], axis=2)


def cylinder_uvs(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F, 3, 2) per-corner coordinates of Blender's cylinder projection (see the module doc)."""
    return _polar_uvs(vertices, faces, local2world, sphere=False)


def sphere_uvs(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F, 3, 2) per-corner coordinates of Blender's sphere projection (see the module doc)."""
    return _polar_uvs(vertices, faces, local2world, sphere=True)


def project_uvs(projection: str, vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F, 3, 2) coordinates of ``projection`` (one of :data:`PROJECTIONS`)."""
    if projection == "cube":
        return cube_uvs(vertices, faces)
    return _polar_uvs(vertices, faces, local2world, sphere=projection == "sphere")


def corner_vertices(faces: np.ndarray, corner_uvs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A mesh's vertices split where its face corners disagree on coordinates: (source vertex index (K,), uvs
    (K, 2), new faces (F, 3)); corners of one vertex with equal coordinates share one new vertex."""
    keys = np.concatenate([np.asarray(faces).reshape(-1, 1).astype(np.float64),
                           np.asarray(corner_uvs, dtype=np.float64).reshape(-1, 2)], axis=1)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return unique[:, 0].astype(np.int64), unique[:, 1:], inverse.reshape(-1, 3).astype(np.int64)
