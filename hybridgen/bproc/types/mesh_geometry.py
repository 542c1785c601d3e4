"""Geometric queries of a ``bproc.types.MeshObject`` (BlenderProc's MeshObjectUtility): its mesh as one hybridgen
mesh, BVH trees, ray casts and the "is this point above me" test, over :mod:`hybridgen.scene.ray_casting`.

Frames: ``create_bvh_tree`` holds the object's triangles in world coordinates at its current pose (metres), as
BlenderProc bakes ``matrix_world`` into the tree; ``ray_cast`` works in the object's own (local) frame, as
Blender's ``Object.ray_cast`` does. Face indices are hybridgen's triangles (Blender counts polygons: a quad is one
face there, two triangles here).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from ...scene.mesh_object import MeshObject as ScenePart
from ...scene.ray_casting import RayCaster
from ..session import SESSION

if TYPE_CHECKING:
    from .bvh_tree import BVHTree

BLENDER_MAX_DISTANCE = 1.70141e+38
"""Blender's default ``distance`` of a ray cast (FLT_MAX / 2)."""


class MeshGeometry:
    """Mixin of :class:`~hybridgen.bproc.types.MeshObject`: needs ``parts``, ``get_name`` and
    ``get_local2world_mat``."""

    parts: list[ScenePart]
    get_name: Callable[[], str]
    get_local2world_mat: Callable[[], np.ndarray]

    def local_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """(vertices (V, 3) in the local frame, triangles (F, 3)) of all parts joined; the same arrays while the
        parts are unchanged (collision checks cache per array)."""
        key = tuple((id(part.vertices), id(part.faces)) for part in self.parts)
        cached = self.__dict__.get("_joined")
        if not self.parts:
            return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
        if cached is None or cached[0] != key:
            offsets = np.cumsum([0] + [len(part.vertices) for part in self.parts])
            vertices = np.concatenate([part.vertices for part in self.parts])
            faces = np.concatenate([part.faces + offset for part, offset in zip(self.parts, offsets)])
            cached = (key, vertices, faces)
            self.__dict__["_joined"] = cached
        return cached[1], cached[2]

    def scene_mesh(self, local2world: np.ndarray | None = None) -> ScenePart:
        """All parts as one hybridgen mesh (no material) at ``local2world`` (default: the current pose): what
        hybridgen's collision checks, placement and physics take."""
        vertices, faces = self.local_mesh()
        pose = self.get_local2world_mat() if local2world is None else local2world
        mesh = ScenePart(self.get_name(), vertices, faces, local2world=np.array(pose, dtype=np.float64))
        return mesh

    def world_triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """(vertices in world coordinates at the current pose, triangles)."""
        vertices, faces = self.local_mesh()
        matrix = self.get_local2world_mat()
        return vertices @ matrix[:3, :3].T + matrix[:3, 3], faces

    def create_bvh_tree(self) -> "BVHTree":
        """A BVH tree of the object's triangles in world coordinates (current pose)."""
        from .bvh_tree import BVHTree

        return BVHTree(RayCaster([self.world_triangles()]))

    def _local_caster(self) -> RayCaster:
        vertices, faces = self.local_mesh()
        cached = self.__dict__.get("_caster")
        if cached is None or cached[0] is not vertices:
            cached = (vertices, RayCaster([(vertices, faces)]))
            self.__dict__["_caster"] = cached
        return cached[1]

    def ray_cast(self, origin: Sequence[float], direction: Sequence[float],
                 max_distance: float = BLENDER_MAX_DISTANCE) -> tuple[bool, np.ndarray, np.ndarray, int]:
        """Cast a ray in the object's local frame: (hit, location, face normal, face index); a miss is
        (False, zeros, zeros, -1) as Blender returns it."""
        hits = self._local_caster().cast(np.asarray(origin, float)[None], np.asarray(direction, float)[None],
                                         max_distance)
        if not hits.hit[0]:
            return False, np.zeros(3), np.zeros(3), -1
        return True, hits.location[0], hits.normal[0], int(hits.face[0])

    def position_is_above_object(self, position: Sequence[float], down_direction: Sequence[float] | None = None,
                                 check_no_objects_in_between: bool = True) -> bool:
        """Whether a ray from ``position`` (world) along ``down_direction`` (default world -Z) hits this object -
        first of all scene objects with ``check_no_objects_in_between``."""
        down = np.array([0.0, 0.0, -1.0] if down_direction is None else down_direction, dtype=np.float64)
        if check_no_objects_in_between:
            hit, _, _, _, hit_object, _ = scene_ray_cast(position, down)
            return bool(hit) and hit_object is self
        world2local = np.linalg.inv(self.get_local2world_mat())
        local = world2local[:3, :3] @ np.asarray(position, dtype=np.float64) + world2local[:3, 3]
        return self.ray_cast(local, world2local[:3, :3] @ down)[0]


def scene_ray_cast(origin: Any, direction: Any, max_distance: float = BLENDER_MAX_DISTANCE) \
        -> tuple[bool, np.ndarray, np.ndarray, int, Any, np.ndarray]:
    """Cast a ray (world) against every mesh object of the scene at its current pose: (hit, location, face
    normal, face index within the hit object, the hit object, its ``matrix_world``); a miss is (False, zeros,
    zeros, -1, None, identity) as Blender returns it."""
    objects = [entity for entity in SESSION.entities if isinstance(entity, MeshGeometry)]
    hits = RayCaster([obj.world_triangles() for obj in objects]).cast(
        np.asarray(origin, dtype=np.float64)[None], np.asarray(direction, dtype=np.float64)[None], max_distance)
    if not hits.hit[0]:
        return False, np.zeros(3), np.zeros(3), -1, None, np.eye(4)
    hit_object = objects[int(hits.mesh[0])]
    return (True, hits.location[0], hits.normal[0], int(hits.face[0]), hit_object,
            hit_object.get_local2world_mat())
