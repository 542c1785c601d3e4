"""``bproc.lighting``: emissive surfaces (``light_surface``) and spot lights that shine into each camera view
(``add_intersecting_spot_lights_to_camera_poses``), over ``bproc.types.Material.make_emissive``, ``bproc.types.Light``
and the scene's BVH tree; ``light_suncg_scene`` raises one line (SUNCG is withdrawn).

Units: emission strength as Blender's Emission Strength (W/m^2 per unit color), spot light energy in W, distances
in metres, world frame. Random draws come from ``np.random`` in BlenderProc 2.8's order.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from ..errors import InputError
from .session import SESSION
from .types import Light, Material, MeshObject
from .types.mesh_object import get_all_mesh_objects
from .types.unsupported import module_getattr


def light_surface(objects: Sequence[MeshObject], emission_strength: float = 10.0,
                  emission_color: Sequence[float] | None = None) -> None:
    """Make every material of ``objects`` emissive (renamed ``<name>_emission``, custom property ``is_lamp``; a
    material other objects use too is copied first); objects without a material share one new ``TextureLess``
    material. Camera rays still see each surface's own material (``make_emissive`` without ``replace``)."""
    shared: Material | None = None
    for obj in objects:
        if not obj.has_materials():
            if shared is not None:
                obj.add_material(shared)
                continue
            shared = obj.new_material("TextureLess")
        for index, material in enumerate(obj.get_materials()):
            if material is None:
                continue
            if material.get_users() > 1:
                material = material.duplicate()
                obj.set_material(index, material)
            material.set_name(material.get_name() + "_emission")
            material.set_cp("is_lamp", True)
            material.make_emissive(emission_strength=emission_strength,
                                   emission_color=None if emission_color is None else list(emission_color))


def _default_light_location(frustum: np.ndarray) -> np.ndarray:
    """A point on a sphere around the frustum's centre, radius 1 % .. 75 % of half its box diagonal."""
    from .sampler import part_sphere

    half_diagonal = np.linalg.norm(frustum.max(axis=0) - frustum.min(axis=0)) * 0.5
    return part_sphere(frustum.mean(axis=0), radius=np.random.uniform(half_diagonal * 0.01, half_diagonal * 0.75),
                       mode="SURFACE")


def _default_look_at(frustum: np.ndarray, _light_location: np.ndarray) -> np.ndarray:
    """The frustum's centre plus a standard normal offset per axis (m)."""
    return frustum.mean(axis=0) + np.random.normal(0, 1.0, 3)


def add_intersecting_spot_lights_to_camera_poses(
        clip_start: float, clip_end: float, perform_look_at_intersection_check: bool = True,
        perform_look_at_pose_visibility_check: bool = True,
        light_pose_sampling: Callable[[np.ndarray], np.ndarray] | None = None,
        look_at_pose_sampling: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
        max_tries_per_cam_pose: int = 10000) -> Light:
    """One SPOT light (energy 10000 W) posed, for each camera frame in turn, outside the camera frustum
    (``clip_start`` .. ``clip_end`` m) looking at a point inside it, with no object between the light and that
    point nor between that point and the camera (the checks switched on). As in BlenderProc the pose is set
    without a keyframe, so the light ends at the pose found for the last frame. Raises one line when a frame has
    no such pose in ``max_tries_per_cam_pose`` tries."""
    from . import camera
    from .bvh_tree import create_bvh_tree_multi_objects
    if SESSION.frame_start == SESSION.frame_end:
        raise InputError("add_intersecting_spot_lights_to_camera_poses: a camera pose has to be set first")
    light_location = light_pose_sampling or _default_light_location
    look_at = look_at_pose_sampling or _default_look_at
    light = Light(light_type="SPOT")
    light.set_energy(10000)
    tree = None
    if perform_look_at_pose_visibility_check or perform_look_at_intersection_check:
        tree = create_bvh_tree_multi_objects(get_all_mesh_objects())
    for frame in range(SESSION.frame_start, SESSION.frame_end):
        frustum = np.asarray(camera.get_camera_frustum(clip_start=clip_start, clip_end=clip_end, frame=frame))
        for _ in range(max_tries_per_cam_pose):
            location = np.asarray(light_location(frustum), dtype=np.float64)
            target = np.asarray(look_at(frustum, location), dtype=np.float64)
            if camera.is_point_inside_camera_frustum(location, frame=frame) or \
                    not camera.is_point_inside_camera_frustum(target, frame=frame):
                continue
            if perform_look_at_pose_visibility_check:
                towards_camera = camera.get_camera_pose(frame)[:3, 3] - target
                if tree.ray_cast(target, towards_camera, np.linalg.norm(towards_camera))[3] is not None:
                    continue
            if perform_look_at_intersection_check:
                towards_target = target - location
                if tree.ray_cast(location, towards_target, np.linalg.norm(towards_target))[3] is not None:
                    continue
            light.set_location(location)
            light.set_rotation_mat(camera.rotation_from_forward_vec(target - location))
            break
        else:
            raise InputError("add_intersecting_spot_lights_to_camera_poses: no pose found, increase the start and "
                             "end clip or increase the amount of tries")
    return light


__getattr__ = module_getattr("lighting", ["light_suncg_scene"])
