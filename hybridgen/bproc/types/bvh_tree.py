"""Blender's ``mathutils.bvhtree.BVHTree`` for ray casts, over :class:`hybridgen.scene.ray_casting.RayCaster`.

A tree holds triangles in world coordinates (metres) as they were when it was built: moving an object later does
not change it, as in Blender. ``BVHTree.ray_cast(origin, direction, distance)`` returns Blender's
``(location, normal, index, distance)`` - location and normal as (3,) arrays (Blender: Vectors; both convert with
``np.array``), the hit triangle's index among the tree's triangles, the distance along the normalised direction -
or ``(None, None, None, None)`` on a miss; ``find_nearest(origin, distance)`` the same for the nearest point.
"""
from __future__ import annotations

import sys
from typing import Any, Sequence

import numpy as np

from ...scene.ray_casting import RayCaster
from .unsupported import fail


class BVHTree:
    """Blender's ``mathutils.bvhtree.BVHTree`` for ray casts (see the module documentation)."""

    def __init__(self, caster: RayCaster) -> None:
        self.caster = caster

    @classmethod
    def FromPolygons(cls, vertices: Sequence[Sequence[float]], polygons: Sequence[Sequence[int]],  # noqa: N802
                     all_triangles: bool = False, epsilon: float = 0.0) -> "BVHTree":
        """A tree of ``polygons`` (vertex index lists, fan-triangulated) over ``vertices``."""
        triangles = [(poly[0], poly[i], poly[i + 1]) for poly in polygons for i in range(1, len(poly) - 1)]
        return cls(RayCaster([(np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64))]))

    def ray_cast(self, origin: Any, direction: Any, distance: float = sys.float_info.max) -> tuple[Any, Any, Any, Any]:
        """The nearest hit along ``direction`` within ``distance`` (see the module documentation)."""
        hits = self.caster.cast(np.asarray(origin, dtype=np.float64)[None],
                                np.asarray(direction, dtype=np.float64)[None], float(distance))
        if not hits.hit[0]:
            return None, None, None, None
        # one tree face index across all its meshes, as a tree built from one joined BMesh counts them
        index = int(np.flatnonzero(self.caster.owner == hits.mesh[0])[0] + hits.face[0])
        return hits.location[0], hits.normal[0], index, float(hits.distance[0])

    def find_nearest(self, origin: Any, distance: float = sys.float_info.max) -> tuple[Any, Any, Any, Any]:
        """The point of the tree's triangles nearest to ``origin`` within ``distance``: Blender's ``(location,
        normal, index, distance)`` - the triangle's normal, its index as :meth:`ray_cast` counts them - or
        ``(None, None, None, None)`` when none is that close."""
        from ...scene.nearest_point import closest_points

        faces = self.caster.faces
        if not len(faces):
            return None, None, None, None
        point = np.asarray(origin, dtype=np.float64).reshape(3)
        corners = self.caster.vertices[faces]
        nearest = closest_points(point, corners[:, 0], corners[:, 1], corners[:, 2])
        gaps = np.linalg.norm(nearest - point, axis=1)
        index = int(np.argmin(gaps))
        if gaps[index] > float(distance):
            return None, None, None, None
        return nearest[index], self.caster.normals[index].copy(), index, float(gaps[index])

    def overlap(self, *_args: Any, **_kwargs: Any) -> Any:
        fail("mathutils.bvhtree.BVHTree.overlap", "bproc.object's collision checks use hybridgen's exact tests")
