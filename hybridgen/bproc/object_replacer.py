"""``bproc.object.replace_objects`` (BlenderProc's ObjectReplacer): objects of a scene swapped for copies of
other objects, tried at the replaced object's pose, kept when they intersect nothing.

As BlenderProc 2.8 does it: the objects to replace with are hidden; ``int(len * replace_ratio)`` objects to
replace are drawn with ``random.sample``; for each, up to ``max_tries`` times, a candidate drawn with
``np.random.choice`` gets the replaced object's location and rotation and, per axis, the ratio of the two local
bound boxes' sides as its scale (:func:`hybridgen.sampling.swapping.fit_scale`, ``per_axis``), then
``relative_pose_sampler(candidate)``; it is accepted when it intersects none of the scene's mesh objects (except
``ignore_collision_with``, itself and the replaced object; the other candidates count where they stand, the
copies made before do not, as in BlenderProc) - hybridgen tests meshes exactly
(:class:`~hybridgen.scene.collision.CollisionWorld`) where Blender intersects BVH trees. An accepted candidate is
duplicated (``name.001``), the copy gets the replaced object's custom properties (``copy_properties``) and is
shown, and the replaced object is deleted. World frame, metres.
"""
from __future__ import annotations

import random
from typing import Callable, Sequence

import numpy as np

from ..logs import LOGGER
from ..sampling.swapping import fit_scale
from ..scene.collision import CollisionWorld
from ..scene.mesh_object import MeshObject as SceneMesh
from .types import MeshObject
from .types.mesh_object import get_all_mesh_objects


class _Obstacles:
    """The collision world of bproc objects, each at its current pose when a test runs."""

    def __init__(self, objects: Sequence[MeshObject]) -> None:
        self.world = CollisionWorld()
        self.objects = list(objects)
        self.meshes: dict[int, SceneMesh] = {}
        self.placed: dict[int, bytes] = {}
        """The pose each object's mesh was added at, by the object's id."""

    def _mesh(self, obj: MeshObject) -> SceneMesh:
        if id(obj) not in self.meshes:
            self.meshes[id(obj)] = obj.scene_mesh()
        return self.meshes[id(obj)]

    def drop(self, obj: MeshObject) -> None:
        """Take ``obj`` out of the world and of later tests."""
        if obj in self.objects:
            self.objects.remove(obj)
        self.world.remove(self._mesh(obj))
        self.placed.pop(id(obj), None)

    def collides(self, query: MeshObject, excluded: Sequence[MeshObject]) -> bool:
        """Whether ``query`` at its pose intersects an object other than ``excluded``."""
        skip = {id(obj) for obj in excluded}
        for obj in self.objects:
            mesh, pose = self._mesh(obj), obj.get_local2world_mat().tobytes()
            if id(obj) in skip or not obj.parts:
                self.world.remove(mesh)
                self.placed.pop(id(obj), None)
            elif self.placed.get(id(obj)) != pose:
                mesh.local2world = obj.get_local2world_mat()
                self.world.add(mesh)
                self.placed[id(obj)] = pose
        return bool(query.parts) and self.world.collides(query.scene_mesh())


def _scale_ratio(original: MeshObject, candidate: MeshObject) -> np.ndarray:
    """Per-axis ratio of the local bound boxes' sides (original / candidate), BlenderProc's rough fit."""
    extent = np.ptp(original.get_bound_box(local_coords=True), axis=0)
    return fit_scale(extent, np.ptp(candidate.get_bound_box(local_coords=True), axis=0), "per_axis")


def replace_objects(objects_to_be_replaced: Sequence[MeshObject], objects_to_replace_with: Sequence[MeshObject],
                    ignore_collision_with: Sequence[MeshObject] | None = None, replace_ratio: float = 1,
                    copy_properties: bool = True, max_tries: int = 100,
                    relative_pose_sampler: Callable[[MeshObject], None] | None = None) -> None:
    """See the module documentation."""
    ignored = list(ignore_collision_with or [])
    for obj in objects_to_replace_with:
        obj.hide()
    obstacles = _Obstacles([obj for obj in get_all_mesh_objects() if obj not in ignored])
    chosen = random.sample(list(objects_to_be_replaced), k=int(len(objects_to_be_replaced) * replace_ratio))
    if not chosen:
        LOGGER.warning("replace_objects: the amount of objects which should be replaced is zero")
    for original in chosen:
        for _ in range(max_tries):
            candidate = np.random.choice(np.array(list(objects_to_replace_with), dtype=object))
            candidate.set_location(original.get_location())
            candidate.set_rotation_euler(original.get_rotation_euler())
            candidate.set_scale(_scale_ratio(original, candidate))
            if relative_pose_sampler is not None:
                relative_pose_sampler(candidate)
            if obstacles.collides(candidate, [candidate, original]):
                continue
            copy = candidate.duplicate()
            if copy_properties:
                for key, value in original.get_all_cps().items():
                    copy.set_cp(key, value)
            copy.hide(False)
            obstacles.drop(original)
            original.delete()
            break
        else:
            LOGGER.info("replace_objects: could not replace %s", original.get_name())
