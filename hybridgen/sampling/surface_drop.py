"""Python API: objects placed on a surface by dropping their bounding boxes onto the surface's (BlenderProc 2's
``sample_poses_on_surface``).

Where :func:`hybridgen.sampling.placement.rest_on_surface` lowers an object until its mesh touches the surface under
it, this places as BlenderProc does: a proposed pose is kept when the object intersects none of the objects placed
before it (exact mesh tests; the surface itself is not an obstacle), when rays from its bound box corners (or its
centre) against ``up`` hit the surface, and - after the drop - when its origin lies ``min_distance`` ..
``max_distance`` m from the nearest placed object's origin. The drop moves the object against ``up`` until the
lowest corner of its oriented bound box (the local axis-aligned box at the pose) is level with the highest corner
of the surface's, so a rotated object ends slightly above the surface (BlenderProc recommends a physics step
afterwards). World frame, metres; ``up`` a unit vector (default world +Z).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..scene.collision import CollisionWorld
from ..scene.mesh_object import MeshObject
from ..scene.ray_casting import RayCaster
from .placement import PlacementResult, Proposal, sample_poses

BOX_CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)])


def bound_box(obj: MeshObject, pose: np.ndarray | None = None) -> np.ndarray:
    """(8, 3) world corners of the object's local axis-aligned box at ``pose`` (default its own)."""
    low, high = obj.bounds_local
    corners = np.where(BOX_CORNERS == 1, high, low)
    pose = obj.local2world if pose is None else pose
    return corners @ pose[:3, :3].T + pose[:3, 3]


def _over_surface(surface: RayCaster, corners: np.ndarray, up: np.ndarray, all_corners: bool) -> bool:
    points = corners if all_corners else corners.mean(axis=0, keepdims=True)
    return bool(surface.cast(points + up, np.tile(-up, (len(points), 1))).hit.all())


def _spaced(location: np.ndarray, placed: Sequence[MeshObject], min_distance: float, max_distance: float) -> bool:
    if not placed:
        return True
    closest = min(float(np.linalg.norm(other.local2world[:3, 3] - location)) for other in placed)
    return min_distance <= closest <= max_distance


def drop_on_surface(objects: Sequence[MeshObject], surface: MeshObject, propose: Proposal, max_tries: int,
                    min_distance: float = 0.25, max_distance: float = 0.6, up: Sequence[float] = (0.0, 0.0, 1.0),
                    all_corners: bool = True) -> PlacementResult:
    """Place ``objects`` in order on ``surface`` (see the module documentation). ``propose(obj)`` gives a 4x4 pose
    per try (None: a failed try). An object without a valid pose in ``max_tries`` goes back to the pose it had and
    is listed in ``failed``; placed objects get their final pose."""
    direction = np.asarray(up, dtype=np.float64)
    direction = direction / np.linalg.norm(direction)
    surface_rays = RayCaster.of_objects([surface])
    surface_top = float((bound_box(surface) @ direction).max())
    undropped: dict[int, np.ndarray] = {}
    before_drop = CollisionWorld()

    def dropped(obj: MeshObject) -> np.ndarray | None:
        pose = propose(obj)
        if pose is None or not _over_surface(surface_rays, bound_box(obj, pose), direction, all_corners):
            return None
        undropped[id(obj)] = pose = np.array(pose, dtype=np.float64)
        pose = pose.copy()
        pose[:3, 3] -= direction * (float((bound_box(obj, pose) @ direction).min()) - surface_top)
        return pose if _over_surface(surface_rays, bound_box(obj, pose), direction, all_corners) else None

    def check(obj: MeshObject, pose: np.ndarray, placed: Sequence[MeshObject]) -> bool:
        for other in placed:
            before_drop.add(other)  # at its final pose; re-adding is cheap (the BVH is kept)
        return _spaced(pose[:3, 3], placed, min_distance, max_distance) and \
            not before_drop.collides(obj, undropped[id(obj)])

    return sample_poses(objects, [], dropped, max_tries, extra_check=check, failed_block=False)
