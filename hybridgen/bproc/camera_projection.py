"""``bproc.camera``'s projections (BlenderProc's CameraProjection): depth by ray casting into a BVH tree, points
projected into the image and image points (with depth) back into the world, point clouds from depth images.

Image coordinates are BlenderProc's: pixel (x, y) has its centre at x + 0.5 px from the image's left edge and y +
0.5 px from its top edge, as hybridgen's intrinsics count (pixel centres at integers, K's principal point at
((W - 1) / 2, (H - 1) / 2) for a centred camera). Depth is metres along the optical axis, distance metres from
the camera centre; world points are metres. ``frame`` picks the camera pose keyed at that frame (None: the
current pose).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..scene.frames import blender_to_opencv
from .session import SESSION, current_intrinsics


def _pose(frame: int | None) -> np.ndarray:
    """The Blender-axes cam2world keyed at ``frame`` (None: the current pose)."""
    return np.array(SESSION.camera.pose.at(frame), dtype=np.float64)


def depth_at_points_via_raytracing(bvh_tree: Any, points_2d: np.ndarray, frame: int | None = None,
                                   return_dist: bool = False) -> np.ndarray:
    """(N,) depth (or, with ``return_dist``, distance) of the first surface of ``bvh_tree`` seen through each of
    the (N, 2) image points (x, y); inf where the ray hits nothing."""
    points_2d = np.asarray(points_2d, dtype=np.float64).reshape(-1, 2)
    intr = current_intrinsics()
    cam2world = blender_to_opencv(_pose(frame))
    local = np.stack([(points_2d[:, 0] - intr.K[0, 2]) / intr.K[0, 0],
                      (points_2d[:, 1] - intr.K[1, 2]) / intr.K[1, 1], np.ones(len(points_2d))], axis=1)
    directions = local @ cam2world[:3, :3].T
    origins = np.broadcast_to(cam2world[:3, 3], directions.shape)
    hits = bvh_tree.caster.cast(origins, directions)
    dists = np.where(hits.hit, hits.distance, np.inf)
    if return_dist:
        return dists
    # BlenderProc's dist2depth at these points: one focal length fx for both axes
    fx, cx, cy = intr.K[0, 0], intr.K[0, 2], intr.K[1, 2]
    return dists * fx / np.sqrt((points_2d[:, 0] - cx) ** 2 + (points_2d[:, 1] - cy) ** 2 + fx ** 2)


def depth_via_raytracing(bvh_tree: Any, frame: int | None = None, return_dist: bool = False) -> np.ndarray:
    """(H, W) depth (or distance) image by one ray through every pixel centre into ``bvh_tree``; inf where a ray
    hits nothing."""
    intr = current_intrinsics()
    x, y = np.meshgrid(np.arange(intr.width), np.arange(intr.height))
    points = np.stack([x, y], axis=-1).astype(np.float32).reshape(-1, 2)
    return depth_at_points_via_raytracing(bvh_tree, points, frame, return_dist).reshape(intr.height, intr.width)


def unproject_points(points_2d: np.ndarray, depth: np.ndarray, frame: int | None = None,
                     depth_cut_off: float = 1e6) -> np.ndarray:
    """(N, 3) world points of the (N, 2) image points at the (N,) depths; NaN where depth > ``depth_cut_off``.
    As BlenderProc, ``points_2d``'s y column is flipped in place (to H - 1 - y) and K's principal point is used
    for the flipped coordinates."""
    intr = current_intrinsics()
    points_2d[..., 1] = (intr.height - 1) - points_2d[..., 1]
    depth = np.asarray(depth, dtype=np.float64)
    homogeneous = np.concatenate([np.asarray(points_2d, dtype=np.float64), np.ones((len(points_2d), 1))], axis=1)
    with np.errstate(invalid="ignore"):
        local = (homogeneous * depth[:, None]) @ np.linalg.inv(intr.K).T
    local[:, 2] *= -1  # Blender camera axes: looking along -z
    cam2world = _pose(frame)
    world = local @ cam2world[:3, :3].T + cam2world[:3, 3]
    world[depth > depth_cut_off] = np.nan
    return world


def project_points(points: np.ndarray, frame: int | None = None) -> np.ndarray:
    """(N, 2) image points (x, y) of the (N, 3) world points (y flipped to H - 1 - y as BlenderProc does)."""
    intr = current_intrinsics()
    world2cam = np.linalg.inv(_pose(frame))
    local = np.asarray(points, dtype=np.float64) @ world2cam[:3, :3].T + world2cam[:3, 3]
    local[:, 2] *= -1
    image = local @ intr.K.T
    image = image[:, :2] / image[:, 2:]
    image[:, 1] = (intr.height - 1) - image[:, 1]
    return image


def pointcloud_from_depth(depth: np.ndarray, frame: int | None = None, depth_cut_off: float = 1e6) -> np.ndarray:
    """(H, W, 3) world points of every pixel of the (H, W) depth image (:func:`unproject_points`)."""
    depth = np.asarray(depth)
    x, y = np.meshgrid(np.arange(depth.shape[1]), np.arange(depth.shape[0]))
    points = np.stack([x, y], axis=-1).astype(np.float32).reshape(-1, 2)
    return unproject_points(points, depth.reshape(-1), frame, depth_cut_off).reshape(depth.shape[0], depth.shape[1],
                                                                                      3)
