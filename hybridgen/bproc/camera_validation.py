"""``bproc.camera``'s checks of what a camera pose sees (BlenderProc's CameraValidation): ``visible_objects``,
``scene_coverage_score``, ``decrease_interest_score``, ``perform_obstacle_in_view_check``.

BlenderProc casts ``sqrt_number_of_rays``\\ :sup:`2` rays from the camera centre through a grid spanning the image
corner to corner. Here that grid is one raster draw of the session's visible mesh objects at their current
poses (:func:`hybridgen.sampling.ray_grid.grid_intrinsics`, drawn by :class:`hybridgen.RasterView`; exact at
the ray directions). Poses are Blender-axes ``cam2world`` 4x4 (metres); the current intrinsics apply. The
scene and its view are kept while the objects stay where they are, so sampling loops draw once per pose.
"""
from __future__ import annotations

from typing import Any, Hashable, Sequence

import numpy as np

from ..errors import InputError
from ..sampling.interest_score import SCORE_ONLY, InterestScore
from ..sampling.ray_grid import grid_intrinsics, grid_rays, obstacle_check_passes, ray_range
from ..scene.frames import blender_to_opencv
from .session import SESSION, current_intrinsics
from .types import MeshObject
from .types.entity import matrix4

_CACHE: dict[str, Any] = {"key": None}
"""The current grid scene: ``key`` (objects and poses it was built for), ``view``, ``objects``."""


def _visible_meshes() -> list[MeshObject]:
    return [e for e in SESSION.entities if isinstance(e, MeshObject) and not e.is_hidden()]


def _view() -> tuple[Any, list[MeshObject]]:
    """The raster view of the visible mesh objects at their current poses (instance id i + 1 = objects[i])."""
    import hybridgen as hg

    from .label_scene import label_scene

    objects = _visible_meshes()
    key = tuple((id(obj), obj.world_matrix(None).tobytes(), len(obj.parts)) for obj in objects)
    if _CACHE["key"] != key:
        if _CACHE.get("view") is not None:
            _CACHE["view"].release()
            _CACHE["view"] = None
        if not objects:
            _CACHE.update(key=key, view=None, objects=[])
        else:
            scene, _ = label_scene([None], objects)  # type: ignore[list-item] - None: the current values
            _CACHE.update(key=key, view=hg.RasterView(scene), objects=objects)
    return _CACHE["view"], _CACHE["objects"]


def cast_grid(cam2world_matrix: Any, sqrt_number_of_rays: int) -> tuple[np.ndarray, np.ndarray, list[MeshObject]]:
    """(instance ids (n, n), 0 = nothing hit; distances (n, n) in m, inf where nothing was hit; the objects, id
    i + 1 being ``objects[i]``) of the grid of rays of the Blender-axes ``cam2world_matrix``."""
    pose = blender_to_opencv(matrix4(cam2world_matrix, "cam2world_matrix"))
    intr = grid_intrinsics(current_intrinsics(), int(sqrt_number_of_rays))
    view, objects = _view()
    if view is None:
        return np.zeros((intr.height, intr.width), np.int64), np.full((intr.height, intr.width), np.inf), []
    drawn = view.render(pose, ["instance_segmaps", "distance"], intrinsics=intr)
    return np.asarray(drawn["instance_segmaps"], np.int64), np.asarray(drawn["distance"], np.float64), objects


def visible_objects(cam2world_matrix: Any, sqrt_number_of_rays: int = 10) -> set[MeshObject]:
    """The mesh objects at least one ray of the grid hits first."""
    ids, _, objects = cast_grid(cam2world_matrix, sqrt_number_of_rays)
    return {objects[i - 1] for i in np.unique(ids).tolist() if i > 0}


def _coverage_group(obj: MeshObject) -> Hashable:
    """The group a ray hitting ``obj`` counts for in BlenderProc's coverage score: SUNCG / 3D-FRONT furniture by
    its ``coarse_grained_class`` (without one: the score only), else the ``category_id`` custom property, else the
    object itself."""
    dataset = obj.has_cp("is_suncg") or obj.has_cp("is_3d_front")
    furniture = (obj.has_cp("suncg_type") and obj.get_cp("suncg_type") == "Object") or \
        (obj.has_cp("3D_future_type") and obj.get_cp("3D_future_type") == "Object")
    if dataset and furniture:
        return ("class", obj.get_cp("coarse_grained_class")) if obj.has_cp("coarse_grained_class") else SCORE_ONLY
    if obj.has_cp("category_id"):
        return ("class", obj.get_cp("category_id"))
    return ("object", id(obj))


def scene_coverage_score(cam2world_matrix: Any, special_objects: Sequence[Any] | None = None,
                         special_objects_weight: float = 2, sqrt_number_of_rays: int = 10) -> float:
    """BlenderProc's interest score of the view (:class:`hybridgen.sampling.interest_score.InterestScore`):
    ``(k / 3) * prod_g (1 - h_g / n^2) * (sum of ray weights / n^2)`` over the ``k`` groups hit (``h_g`` rays
    each); rays on ``special_objects`` (category ids or coarse classes) weigh ``special_objects_weight``."""
    ids, _, objects = cast_grid(cam2world_matrix, sqrt_number_of_rays)
    score = InterestScore(0.0, {index + 1: _coverage_group(obj) for index, obj in enumerate(objects)},
                          frozenset(("class", s) for s in (special_objects or [])), float(special_objects_weight),
                          int(sqrt_number_of_rays))
    return score.score(ids)


def decrease_interest_score(interest_score: float, min_interest_score: float,
                            interest_score_step: float) -> tuple[bool, float]:
    """(False, the score) once ``interest_score`` is at or below ``min_interest_score``, else (True, the score
    lowered by ``interest_score_step``)."""
    if interest_score <= min_interest_score:
        return False, interest_score
    return True, interest_score - interest_score_step


def perform_obstacle_in_view_check(cam2world_matrix: Any, proximity_checks: dict, bvh_tree: Any,
                                   sqrt_number_of_rays: int = 10) -> bool:
    """Whether the grid's hits in ``bvh_tree`` pass ``proximity_checks`` (``min``/``max`` m, ``avg``/``var``
    ``{min, max}``, ``no_background``; :func:`hybridgen.sampling.ray_grid.obstacle_check_passes`). ``bvh_tree``
    is what ``bproc.object.create_bvh_tree_multi_objects`` returns: anything with Blender's
    ``ray_cast(origin, direction, distance)`` -> ``(location, normal, index, distance or None)``."""
    if not proximity_checks:
        return True
    if not callable(getattr(bvh_tree, "ray_cast", None)):
        raise InputError("perform_obstacle_in_view_check needs the BVH tree of bproc.object."
                         f"create_bvh_tree_multi_objects (an object with ray_cast), got {type(bvh_tree).__name__}")
    reach = ray_range(proximity_checks)
    pose = blender_to_opencv(matrix4(cam2world_matrix, "cam2world_matrix"))
    origin, directions = grid_rays(current_intrinsics(), int(sqrt_number_of_rays), pose)
    caster = getattr(bvh_tree, "caster", None)  # hybridgen's tree: its RayCaster casts the grid at once
    if callable(getattr(caster, "cast", None)):
        hits = caster.cast(np.repeat(origin[None], len(directions), axis=0), directions, reach)
        return obstacle_check_passes(np.asarray(hits.distance), np.asarray(hits.hit, bool), proximity_checks)
    distance = np.zeros(len(directions))
    hit = np.zeros(len(directions), bool)
    for index, direction in enumerate(directions):
        found = bvh_tree.ray_cast(origin, direction) if np.isinf(reach) else \
            bvh_tree.ray_cast(origin, direction, reach)
        if found is not None and found[3] is not None:
            hit[index], distance[index] = True, float(found[3])
    return obstacle_check_passes(distance, hit, proximity_checks)
