"""Ray casts against a fixed set of triangles (trimesh; Embree when ``embreex`` is
installed, else trimesh's exact NumPy intersector).

A :class:`RayCaster` holds triangles in one frame (usually the world, metres) with the index of the mesh each
triangle came from, so a cast says which mesh and which of its triangles a ray hit first. Rays start at their
origin and run forward along their direction (any length; normalised here) up to ``max_distance`` along it.
The normal of a hit is the hit triangle's geometric normal (from its winding), unit length, in the same frame.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .mesh_object import MeshObject


@dataclass
class RayHits:
    """Per ray: ``hit`` (bool), and where hit: ``location`` (3,), ``normal`` (3,), ``face`` (triangle index within
    its mesh), ``mesh`` (index of the mesh), ``distance`` (along the unit direction). Misses hold NaN / -1."""

    hit: np.ndarray
    location: np.ndarray
    normal: np.ndarray
    face: np.ndarray
    mesh: np.ndarray
    distance: np.ndarray


class RayCaster:
    """Ray casts against the triangles of ``meshes``: (vertices (V, 3), faces (F, 3)) pairs in one frame."""

    def __init__(self, meshes: Sequence[tuple[np.ndarray, np.ndarray]]) -> None:
        import trimesh

        vertices, faces, owner, local_face, offset = [], [], [], [], 0
        for index, (mesh_vertices, mesh_faces) in enumerate(meshes):
            mesh_vertices = np.asarray(mesh_vertices, dtype=np.float64).reshape(-1, 3)
            mesh_faces = np.asarray(mesh_faces, dtype=np.int64).reshape(-1, 3)
            vertices.append(mesh_vertices)
            faces.append(mesh_faces + offset)
            owner.append(np.full(len(mesh_faces), index))
            local_face.append(np.arange(len(mesh_faces)))
            offset += len(mesh_vertices)
        self.vertices = np.concatenate(vertices) if vertices else np.zeros((0, 3))
        self.faces = np.concatenate(faces) if faces else np.zeros((0, 3), dtype=np.int64)
        self.owner = np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64)
        self.local_face = np.concatenate(local_face) if local_face else np.zeros(0, dtype=np.int64)
        self.mesh: Any = trimesh.Trimesh(self.vertices, self.faces, process=False) if len(self.faces) else None
        corners = self.vertices[self.faces]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        length = np.linalg.norm(normals, axis=1, keepdims=True)
        self.normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)

    @classmethod
    def of_objects(cls, objects: Sequence[MeshObject]) -> "RayCaster":
        """The objects' triangles in world coordinates (each at its ``local2world``); ``mesh`` indexes
        ``objects``."""
        return cls([(obj.world_vertices(), obj.faces) for obj in objects])

    def cast(self, origins: Any, directions: Any, max_distance: float = np.inf) -> RayHits:
        """The first triangle each ray hits within ``max_distance`` (see the module documentation)."""
        origins = np.atleast_2d(np.asarray(origins, dtype=np.float64))
        directions = np.atleast_2d(np.asarray(directions, dtype=np.float64))
        length = np.linalg.norm(directions, axis=1, keepdims=True)
        directions = np.divide(directions, length, out=np.zeros_like(directions), where=length > 0)
        count = len(origins)
        hits = RayHits(np.zeros(count, bool), np.full((count, 3), np.nan), np.full((count, 3), np.nan),
                       np.full(count, -1), np.full(count, -1), np.full(count, np.nan))
        if self.mesh is None or count == 0:
            return hits
        triangles, rays, locations = self.mesh.ray.intersects_id(origins, directions, multiple_hits=False,
                                                                 return_locations=True)
        distance = np.einsum("ij,ij->i", locations - origins[rays], directions[rays])
        keep = (distance >= 0) & (distance <= max_distance)
        chosen, triangles = rays[keep], triangles[keep]
        hits.hit[chosen] = True
        hits.location[chosen] = locations[keep]
        hits.normal[chosen] = self.normals[triangles]
        hits.face[chosen] = self.local_face[triangles]
        hits.mesh[chosen] = self.owner[triangles]
        hits.distance[chosen] = distance[keep]
        return hits

