"""Blender's shading modes for a mesh: the vertex normals color and the normals label interpolate.

- ``FLAT``: no vertex normals (every pixel shows its face's geometric normal).
- ``SMOOTH``: one normal per vertex position, the corner-angle-weighted mean of the normals of the faces around
  it (Blender's vertex normals), so seams the file splits vertices at (UVs, materials) shade smoothly too.
- ``AUTO``: Blender's auto smooth: a corner's normal averages (angle-weighted) the faces around its vertex
  whose normals lie within ``angle_deg`` of its own face's normal; sharper edges stay sharp. Corners are
  split where their normals differ (vertex count grows; UVs and vertex colors follow).

All normals are in the object's local frame; the mesh's shape is unchanged.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SHADING_MODES = ("FLAT", "SMOOTH", "AUTO")


@dataclass(frozen=True)
class ShadedMesh:
    """Arrays of a shaded mesh: ``vertex_normals`` None for FLAT; the others as given unless AUTO split
    corners (then per corner of ``faces``)."""

    vertices: np.ndarray
    faces: np.ndarray
    vertex_normals: np.ndarray | None
    uvs: np.ndarray | None
    vertex_colors: np.ndarray | None


def _corner_weights(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, 3) unit face normals and (F, 3) corner angles (radians)."""
    tri = vertices[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    angles = np.empty(faces.shape)
    for corner in range(3):
        a = tri[:, (corner + 1) % 3] - tri[:, corner]
        b = tri[:, (corner + 2) % 3] - tri[:, corner]
        cos = np.einsum("ij,ij->i", a, b) / np.maximum(np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-300)
        angles[:, corner] = np.arccos(np.clip(cos, -1.0, 1.0))
    return normals, angles


def _unit(vectors: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(vectors, axis=1, keepdims=True)
    return np.where(length > 1e-12, vectors / np.maximum(length, 1e-300), fallback)


def shade(vertices: np.ndarray, faces: np.ndarray, mode: str, angle_deg: float = 30.0,
          uvs: np.ndarray | None = None, vertex_colors: np.ndarray | None = None) -> ShadedMesh:
    """The mesh shaded with ``mode`` (see the module doc)."""
    mode = mode.upper()
    if mode not in SHADING_MODES:
        raise ValueError(f"shading mode must be one of {', '.join(SHADING_MODES)}, got {mode!r}")
    if mode == "FLAT":
        return ShadedMesh(vertices, faces, None, uvs, vertex_colors)
    face_normals, angles = _corner_weights(vertices, faces)
    _, position = np.unique(np.round(vertices, 9), axis=0, return_inverse=True)
    position = position.ravel()
    corner_position = position[faces]  # (F, 3) welded vertex of each corner
    weighted = face_normals[:, None, :] * angles[:, :, None]  # (F, 3, 3) per corner
    if mode == "SMOOTH":
        summed = np.zeros((position.max() + 1, 3))
        np.add.at(summed, corner_position.ravel(), weighted.reshape(-1, 3))
        normals = summed[position]
        fallback = np.zeros_like(normals)
        np.add.at(fallback, faces.ravel(), np.repeat(face_normals, 3, axis=0))
        return ShadedMesh(vertices, faces, _unit(normals, _unit(fallback, np.array([0.0, 0.0, 1.0]))), uvs,
                          vertex_colors)
    # AUTO: per corner, the faces around its welded vertex within the angle of its own face
    cos_limit = np.cos(np.radians(angle_deg))
    corners = corner_position.ravel()
    corner_face = np.repeat(np.arange(len(faces)), 3)
    order = np.argsort(corners, kind="stable")
    starts = np.searchsorted(corners[order], np.arange(position.max() + 2))
    corner_normals = np.empty((len(corners), 3))
    flat_weighted = weighted.reshape(-1, 3)
    for welded in range(position.max() + 1):
        members = order[starts[welded]:starts[welded + 1]]
        if not len(members):
            continue
        own = face_normals[corner_face[members]]
        close = own @ own.T >= cos_limit - 1e-12  # (m, m): corner i takes corner j's face
        corner_normals[members] = _unit(close.astype(float) @ flat_weighted[members], own)
    flat_faces = faces.ravel()
    new_vertices = vertices[flat_faces]
    new_uvs = None if uvs is None else np.asarray(uvs)[flat_faces]
    new_colors = None if vertex_colors is None else np.asarray(vertex_colors)[flat_faces]
    return ShadedMesh(new_vertices, np.arange(len(flat_faces)).reshape(-1, 3), corner_normals, new_uvs, new_colors)
