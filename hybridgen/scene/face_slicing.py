"""Picking a mesh's faces by direction and height, and splitting them off into a mesh of their own (floors and
ceilings of scenes loaded as one mesh, the top surface of a table).

Frames: faces are tested in world coordinates (metres): a face's normal is its geometric normal (right-hand rule)
turned into the world by the inverse transpose of the pose, its height the world z of the mean of its corners.
"""
from __future__ import annotations

import numpy as np

from .mesh_object import MeshObject


def split_faces(obj: MeshObject, keep: np.ndarray, name: str) -> MeshObject:
    """A new object of ``obj``'s faces where ``keep`` is True (unused vertices dropped; same pose, material)."""
    faces = obj.faces[keep]
    used, remapped = np.unique(faces, return_inverse=True)
    return MeshObject(
        name=name, vertices=obj.vertices[used], faces=remapped.reshape(-1, 3),
        vertex_normals=None if obj.vertex_normals is None else obj.vertex_normals[used],
        uvs=None if obj.uvs is None else np.asarray(obj.uvs)[used], material=obj.material,
        category_id=obj.category_id, attributes=dict(obj.attributes), local2world=obj.local2world.copy())


def world_face_normals(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F, 3) unit world normals of the local-frame triangles; (0, 0, 0) for a zero-area face."""
    tri = np.asarray(vertices, dtype=np.float64)[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) @ np.linalg.inv(local2world[:3, :3])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, length, out=np.zeros_like(normals), where=length > 1e-12)


def facing(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray, up: np.ndarray,
           max_angle: float) -> np.ndarray:
    """(F,) bool: faces whose world normal is less than ``max_angle`` rad from the unit vector ``up`` (zero-area
    faces never)."""
    normals = world_face_normals(vertices, faces, local2world)
    cosine = np.clip(normals @ np.asarray(up, dtype=np.float64), -1.0, 1.0)
    return np.any(normals != 0, axis=1) & (np.arccos(cosine) < max_angle)


def face_heights(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F,) world z (m) of each face's corner mean."""
    centres = np.asarray(vertices, dtype=np.float64)[faces].mean(axis=1)
    return centres @ local2world[2, :3] + local2world[2, 3]


def face_areas(vertices: np.ndarray, faces: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """(F,) world areas (m^2)."""
    tri = np.asarray(vertices, dtype=np.float64)[faces] @ local2world[:3, :3].T
    return np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
