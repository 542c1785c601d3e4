"""Python API: collision-free object placement (BlenderProc's ObjectPoseSampler and OnSurfaceSampler)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ..errors import InputError
from ..scene.frames import object_pose
from ..scene.collision import CollisionWorld
from ..scene.mesh_object import MeshObject


@dataclass
class PlacementResult:
    """Which objects found a pose, which did not, and the tries spent."""

    placed: list[MeshObject]
    failed: list[MeshObject]
    tries: int


def scale_of(obj: MeshObject) -> np.ndarray:
    """Per-axis scale of the object's current pose (kept when it is re-posed)."""
    return np.linalg.norm(obj.local2world[:3, :3], axis=0)


Proposal = Callable[[MeshObject], "np.ndarray | None"]
Check = Callable[[MeshObject, np.ndarray, Sequence[MeshObject]], bool]


def sample_poses(objects: Sequence[MeshObject], obstacles: Sequence[MeshObject], propose: Proposal,
                 max_tries: int, extra_check: Check | None = None, keep_last: bool = False,
                 failed_block: bool = True) -> PlacementResult:
    """Give each object, in order, the first proposed 4x4 pose (``propose`` may return None for a failed
    try) whose mesh intersects neither the obstacles nor the objects placed before it and that passes
    ``extra_check(obj, pose, placed_so_far)``. An object without such a pose in ``max_tries`` keeps its old
    pose - or, with ``keep_last``, takes the last pose proposed (BlenderProc's ``mode_on_failure='last_pose'``) -
    is listed in ``failed``, and later objects avoid it there (unless ``failed_block`` is False).
    ``PlacementResult.tries`` counts every try."""
    world = CollisionWorld([o for o in obstacles if o not in objects])
    placed: list[MeshObject] = []
    failed: list[MeshObject] = []
    tries = 0
    for obj in objects:
        last = None
        for _ in range(max_tries):
            tries += 1
            pose = propose(obj)
            last = pose if pose is not None else last
            if pose is None or world.collides(obj, pose) or \
                    (extra_check is not None and not extra_check(obj, pose, placed)):
                continue
            obj.local2world = pose
            world.add(obj)
            placed.append(obj)
            break
        else:
            failed.append(obj)
            if keep_last and last is not None:
                obj.local2world = last
            if failed_block:
                world.add(obj)
    return PlacementResult(placed, failed, tries)


class SurfaceProbe:
    """Heights of a surface object's top (world, m) under query points, by ray casting straight down."""

    def __init__(self, surface: MeshObject) -> None:
        import trimesh

        self.mesh = trimesh.Trimesh(surface.world_vertices(), surface.faces, process=False)
        self.top = float(self.mesh.bounds[1, 2]) + 1.0

    def heights(self, xy: np.ndarray) -> np.ndarray:
        """(K,) height of the highest surface point above each (x, y); NaN where the ray misses."""
        xy = np.atleast_2d(np.asarray(xy, dtype=np.float64))
        origins = np.column_stack([xy, np.full(len(xy), self.top)])
        directions = np.tile([0.0, 0.0, -1.0], (len(xy), 1))
        hits, rays, _ = self.mesh.ray.intersects_location(origins, directions, multiple_hits=False)
        out = np.full(len(xy), np.nan)
        out[rays] = hits[:, 2]
        return out


def rest_on_surface(obj: MeshObject, probe: SurfaceProbe, location: np.ndarray, rotation: np.ndarray,
                    margin: float = 1e-4) -> np.ndarray | None:
    """The pose with ``rotation`` at (x, y) of ``location`` whose lowest point rests ``margin`` m above the
    surface, if the object's whole footprint (its world box corners and centre) lies over it; else None."""
    pose = object_pose(location, rotation, scale_of(obj))
    points = obj.vertices @ pose[:3, :3].T + pose[:3, 3]
    low, high = points.min(axis=0), points.max(axis=0)
    footprint = np.array([[low[0], low[1]], [low[0], high[1]], [high[0], low[1]], [high[0], high[1]],
                          pose[:2, 3]])
    heights = probe.heights(footprint)
    if np.isnan(heights).any():
        return None
    pose[2, 3] += heights.max() + margin - low[2]
    return pose


def check_spacing(min_distance: float, max_distance: float) -> Check:
    """A check that the candidate's origin lies ``min_distance``..``max_distance`` m (in XY) from the
    closest already placed object's origin (BlenderProc's OnSurfaceSampler spacing)."""
    if min_distance > max_distance:
        raise InputError(f"min_distance {min_distance} > max_distance {max_distance}")

    def check(obj: MeshObject, pose: np.ndarray, placed: Sequence[MeshObject]) -> bool:
        others = [o.local2world[:2, 3] for o in placed if o is not obj]
        if not others:
            return True
        gaps = np.linalg.norm(np.array(others) - pose[:2, 3], axis=1)
        return bool(min_distance <= gaps.min() <= max_distance)

    return check
