"""``object.CalibrationboardSampler``: calibration-board poses across the camera view, one keypoint each.

As BlenderProc runs it: the board (the objects named ``board_name``, moved together) is stepped over a grid
of locations on each of ``z_planes`` (world z, metres), x from ``x_min`` to ``x_max`` and y from ``y_min`` to
``y_max`` - once from the minimum corner upwards and once from the maximum corner downwards (``x_min * -1`` ...
as BlenderProc mirrors the bounds), so poses reach every border of the image. Each grid location gets a
rotation drawn from ``rot_sampler`` (Blender XYZ Euler, radians); the pose is kept when every point of
``corner_coords`` (board-local coordinates, metres) projects strictly inside the image of the camera's first
keypoint (BlenderProc's ``0 < x < 1`` of the normalized view: pixel centres u in (-0.5, width - 0.5), v
likewise) and lies in front of it. Steps are ``small_step_size`` (m) while outside the view and
``big_step_size * |z|`` for the next step after a kept pose.

Every kept pose is one keypoint: the camera keeps its first pose for all of them (BlenderProc renders frames
0..N-1 with the camera's keyframe held), the board's pose per keypoint is recorded in the scene's
:class:`~hybridgen.scene.object_keyframes.ObjectKeyframes`. BlenderProc does not test that the corners are in
front of the camera (a point behind it projects mirrored); hybridgen does.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..errors import InputError
from ..run.context import RunContext
from ..sampling.placement import scale_of
from ..scene.camera import Intrinsics
from ..scene.frames import object_pose
from ..scene.object_keyframes import ObjectKeyframes
from .base import Module, Role


def _points(value: Any) -> str | None:
    ok = isinstance(value, list) and value and all(isinstance(p, list) and len(p) == 3 and
                                                    all(isinstance(c, (int, float)) for c in p) for p in value)
    return None if ok else "must be a non-empty list of [x, y, z] points (board-local, metres)"


def points_in_view(points_world: np.ndarray, world2cam: np.ndarray, intrinsics: Intrinsics) -> bool:
    """Whether every point lies in front of the camera and projects strictly inside the image (its outer
    pixel edges: u in (-0.5, width - 0.5), v in (-0.5, height - 0.5))."""
    cam = points_world @ world2cam[:3, :3].T + world2cam[:3, 3]
    if np.any(cam[:, 2] <= 0):
        return False
    pixels = cam @ intrinsics.K.T
    u, v = pixels[:, 0] / pixels[:, 2], pixels[:, 1] / pixels[:, 2]
    return bool(np.all((u > -0.5) & (u < intrinsics.width - 0.5) & (v > -0.5) & (v < intrinsics.height - 0.5)))


@register_module("object.CalibrationboardSampler")
class CalibrationboardSampler(Module):
    """Steps a calibration board over the camera view; every pose that shows all its corners is a keypoint."""

    role = Role.MANIPULATOR

    params = (
        Param("board_name", "str", doc="name of the board object(s)"),
        Param("corner_coords", "list", check=_points, doc="board-local points that must stay in view (m)"),
        Param("rot_sampler", "vec3", [0.0, 0.0, 0.0], "rad", "board rotation (Euler XYZ), drawn per grid location",
              sampleable=True),
        Param("small_step_size", "float", 0.1, "m", "grid step while the board is outside the view", check=positive),
        Param("big_step_size", "float", 0.2, "m", "step after a kept pose, times |z|", check=positive),
        Param("x_min", "float", -5.0, "m"),
        Param("x_max", "float", 5.0, "m"),
        Param("y_min", "float", -5.0, "m"),
        Param("y_max", "float", 5.0, "m"),
        Param("z_planes", "list", [-1.0, -2.0, -3.0], "m", "world heights the board is stepped over"),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        scene = context.scene
        board = [o for o in scene.objects if o.name == cfg["board_name"]]
        if not board:
            raise InputError(f"board_name: no object named '{cfg['board_name']}' in the scene")
        if not len(scene.camera):
            raise InputError("the board is posed in the camera's view: give the camera a pose first "
                             "(camera.CameraLoader)")
        world2cam = scene.camera.world2cam(0)
        corners = np.asarray(cfg["corner_coords"], float)
        reference = board[0].local2world.copy()
        offsets = [np.linalg.inv(reference) @ part.local2world for part in board]
        scale = scale_of(board[0])
        poses = []
        for z in (float(v) for v in cfg["z_planes"]):
            poses += self._scan(context, z, corners, world2cam, scale)
        if not poses:
            raise InputError("no board pose keeps every corner_coords point in the camera's view: widen "
                             "x_min..x_max, y_min..y_max or change z_planes")
        keyframes = ObjectKeyframes()
        for index, pose in enumerate(poses):
            for part, offset in zip(board, offsets):
                part.local2world = pose @ offset
            keyframes.record(scene, index)
        for part, offset in zip(board, offsets):
            part.local2world = poses[0] @ offset
        scene.object_keyframes = keyframes
        first = scene.camera.keypoints[0]
        scene.camera.keypoints[:] = [first.copy() for _ in poses]
        if scene.camera.intrinsics_per_keypoint:
            scene.camera.intrinsics_per_keypoint[:] = [scene.camera.intrinsics_per_keypoint[0]] * len(poses)
        context.log(f"{self.module_name}: {len(poses)} board poses")

    def _scan(self, context: RunContext, z: float, corners: np.ndarray, world2cam: np.ndarray,
              scale: np.ndarray) -> list[np.ndarray]:
        """The kept poses of one z plane, both scan directions."""
        cfg = self.config
        small, big = cfg["small_step_size"], cfg["big_step_size"]
        intrinsics = context.scene.camera.intrinsics
        kept = []
        step_x = step_y = small
        for direction in (1.0, -1.0):
            x = cfg["x_min"] * direction
            while x * direction < cfg["x_max"]:
                y = cfg["y_min"] * direction
                while y * direction < cfg["y_max"]:
                    pose = object_pose([x, y, z], self.value(context, "rot_sampler"), scale)
                    if points_in_view(corners @ pose[:3, :3].T + pose[:3, 3], world2cam, intrinsics):
                        step_x = step_y = big * abs(z)
                        kept.append(pose)
                    y += step_y * direction
                    step_y = small
                x += step_x * direction
                step_x = small
        return kept
