"""``bproc.object.sample_poses`` and ``sample_poses_on_surface`` (BlenderProc's ObjectPoseSampler and
OnSurfaceSampler) over :func:`hybridgen.sampling.placement.sample_poses` and
:func:`hybridgen.sampling.surface_drop.drop_on_surface`.

The script's ``sample_pose_func(obj)`` poses the object itself, once per try, as in BlenderProc, so its own
``np.random`` draws happen in BlenderProc's order; hybridgen tests each pose with exact mesh-mesh intersection and
containment (FCL) where Blender intersects BVH trees and tests one vertex for containment. World frame, metres.
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ..errors import InputError
from ..sampling.placement import sample_poses as place
from ..sampling.surface_drop import drop_on_surface
from ..scene.mesh_object import MeshObject as SceneMesh
from .types import Entity, MeshObject
from .types.mesh_object import get_all_mesh_objects

FAILURE_MODES = ("last_pose", "initial_pose")


class _Proposals:
    """hybridgen meshes standing for the bproc objects, and the proposal that calls the script's function."""

    def __init__(self, objects: Sequence[MeshObject], sample_pose_func: Callable[[MeshObject], None]) -> None:
        self.meshes: dict[int, SceneMesh] = {}
        self.owners: dict[int, MeshObject] = {}
        self.calls: dict[int, int] = {}
        self.func = sample_pose_func
        for obj in objects:
            self.mesh(obj)

    def mesh(self, obj: MeshObject) -> SceneMesh:
        if id(obj) not in self.meshes:
            mesh = obj.scene_mesh()
            self.meshes[id(obj)], self.owners[id(mesh)], self.calls[id(obj)] = mesh, obj, 0
        return self.meshes[id(obj)]

    def __call__(self, mesh: SceneMesh) -> np.ndarray:
        obj = self.owners[id(mesh)]
        self.calls[id(obj)] += 1
        self.func(obj)
        return obj.get_local2world_mat()


def sample_poses(objects_to_sample: Sequence[MeshObject], sample_pose_func: Callable[[MeshObject], None],
                 objects_to_check_collisions: Sequence[MeshObject] | None = None, max_tries: int = 1000,
                 mode_on_failure: str = "last_pose") -> dict[Entity, tuple[int, bool]]:
    """Pose each object, in order, with ``sample_pose_func`` until it intersects none of
    ``objects_to_check_collisions`` (default: every mesh object) nor the objects sampled before it. Returns
    ``{obj: (tries, placed)}`` as BlenderProc does: the index of the successful try, or ``max_tries`` and False
    (the object then stays at its last pose, or goes back to its initial location and rotation with
    ``mode_on_failure='initial_pose'``)."""
    if mode_on_failure not in FAILURE_MODES:
        raise InputError(f"sample_poses: {mode_on_failure} is not an allowed mode_on_failure "
                         f"({', '.join(FAILURE_MODES)})")
    if max_tries <= 0:
        raise InputError(f"sample_poses: the value of max_tries must be greater than zero: {max_tries}")
    if not objects_to_sample:
        raise InputError("sample_poses: the list of objects_to_sample can not be empty")
    obstacles = get_all_mesh_objects() if objects_to_check_collisions is None else objects_to_check_collisions
    initial = {id(obj): (obj.get_location(), obj.get_rotation_euler()) for obj in objects_to_sample}
    proposals = _Proposals(objects_to_sample, sample_pose_func)
    result = place([proposals.mesh(obj) for obj in objects_to_sample], [proposals.mesh(obj) for obj in obstacles],
                   proposals, max_tries, keep_last=mode_on_failure == "last_pose")
    placed = {id(mesh) for mesh in result.placed}
    outcome: dict[Entity, tuple[int, bool]] = {}
    for obj in objects_to_sample:
        if id(proposals.mesh(obj)) in placed:
            outcome[obj] = (proposals.calls[id(obj)] - 1, True)
            continue
        outcome[obj] = (max_tries, False)
        if mode_on_failure == "initial_pose":
            obj.set_location(initial[id(obj)][0])
            obj.set_rotation_euler(initial[id(obj)][1])
    return outcome


def sample_poses_on_surface(objects_to_sample: Sequence[MeshObject], surface: MeshObject,
                            sample_pose_func: Callable[[MeshObject], None], max_tries: int = 100,
                            min_distance: float = 0.25, max_distance: float = 0.6,
                            up_direction: Any = None, check_all_bb_corners_over_surface: bool = True) \
        -> list[MeshObject]:
    """Place each object on ``surface``: posed by ``sample_pose_func``, then dropped along ``-up_direction``
    until its bound box rests on the surface's, apart from the objects placed before it by ``min_distance`` ..
    ``max_distance`` m (origin to origin) and intersecting none of them. An object without such a pose in
    ``max_tries`` goes back to its initial pose and is hidden. Returns the placed objects."""
    if len({id(obj) for obj in objects_to_sample}) != len(objects_to_sample):
        raise InputError("sample_poses_on_surface: the given list of objects to sample contains duplicates")
    up = np.array([0.0, 0.0, 1.0] if up_direction is None else up_direction, dtype=np.float64)
    initial = {id(obj): obj.get_local2world_mat() for obj in objects_to_sample}
    proposals = _Proposals(objects_to_sample, sample_pose_func)
    meshes = [proposals.mesh(obj) for obj in objects_to_sample]
    result = drop_on_surface(meshes, surface.scene_mesh(), proposals, max_tries, min_distance, max_distance,
                             up / np.linalg.norm(up), check_all_bb_corners_over_surface)
    placed = {id(mesh) for mesh in result.placed}
    for obj, mesh in zip(objects_to_sample, meshes):
        if id(mesh) in placed:  # the drop moved it from where sample_pose_func put it
            obj.set_location(obj.get_location() + mesh.local2world[:3, 3] - obj.get_local2world_mat()[:3, 3])
        else:
            obj.hide(True)
            obj.set_local2world_mat(initial[id(obj)])
    return [proposals.owners[id(mesh)] for mesh in result.placed]
