"""Label passes derived from the raster depth and ids with the camera geometry: optical flow, object
coordinates and NOCS.

Optical flow (pixels, float32 H x W x 2): for the surface point seen at pixel centre (u, v) of keypoint i,
its image position in keypoint j minus (u, v) - forward: j = i + 1, backward: j = i - 1. The point moves with
its object: where objects change pose between keypoints (:mod:`hybridgen.scene.object_keyframes`), the
object-local point is placed with the object's pose at j (``motion``: world -> world per instance id); other
points are static and move in the image only with the camera. ``*_flow_occluded`` (uint8) is 1 where that
point is not visible in keypoint j: something else is in front of it there (its depth in j is more than
1 % + 1 mm behind the surface j sees at the nearest pixel), it leaves j's image or crosses j's near plane,
or there is no surface (background), or there is no keypoint j. Flow is 0 where it is undefined (background,
no keypoint j). Keypoint j's own intrinsics (per-keypoint intrinsics) project the point there.

Object coordinates (float32 H x W x 3, m, NaN on the background): the surface point in its object's local
frame. NOCS (float32 H x W x 3, background 0): those coordinates normalized as in the NOCS paper:
``(p_local - box_centre) / box_diagonal + 0.5`` with the object's local bounding box.
"""
from __future__ import annotations

from typing import Any, Iterator, Mapping

import numpy as np

from ...scene.camera import Intrinsics
from ...scene.scene import Scene
from .readback import RasterOutput

OCCLUSION_RELATIVE = 0.01
OCCLUSION_ABSOLUTE = 1e-3  # m


def camera_points(raw: RasterOutput, intr: Intrinsics) -> np.ndarray:
    """(H, W, 3) float64 OpenCV camera coordinates of the surface at every pixel centre (NaN: background)."""
    with np.errstate(invalid="ignore"):  # a packed readback holds the depth background (inf) off surfaces
        points = intr.pixel_rays() * raw.z[..., None].astype(np.float64)
    points[~raw.hit] = np.nan
    return points


def optical_flow(raw: RasterOutput, intr: Intrinsics, pose_from: np.ndarray, pose_to: np.ndarray | None,
                 depth_to: np.ndarray | None, motion: Mapping[int, np.ndarray] | None = None,
                 intr_to: Intrinsics | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Flow (H, W, 2) from keypoint ``pose_from`` to ``pose_to`` and its occlusion mask (H, W) uint8.

    ``depth_to`` is the z-depth image (inf background) rendered at ``pose_to`` with the objects at their poses
    there; ``motion``: instance id -> 4x4 world -> world map of the objects that move between the two
    keypoints (``local2world`` at j @ inverse ``local2world`` at i; absent: static); ``intr_to``: keypoint j's
    intrinsics when they differ from keypoint i's ``intr`` (same image size)."""
    height, width = raw.instance.shape
    flow = np.zeros((height, width, 2), np.float32)
    occluded = np.ones((height, width), np.uint8)
    if pose_to is None or depth_to is None:
        return flow, occluded
    world2cam_to = np.linalg.inv(pose_to)
    relative = world2cam_to @ pose_from  # camera i -> camera j
    here = camera_points(raw, intr)
    points = here @ relative[:3, :3].T + relative[:3, 3]
    for instance_id, moved in (motion or {}).items():
        mask = raw.instance == instance_id
        if mask.any():
            carried = world2cam_to @ moved @ pose_from  # camera i -> the object's place at j -> camera j
            points[mask] = here[mask] @ carried[:3, :3].T + carried[:3, 3]
    z = points[..., 2]
    to = intr if intr_to is None else intr_to
    with np.errstate(invalid="ignore", divide="ignore"):
        u = to.K[0, 0] * points[..., 0] / z + to.K[0, 2]
        v = to.K[1, 1] * points[..., 1] / z + to.K[1, 2]
    grid_v, grid_u = np.mgrid[0:height, 0:width]
    defined = raw.hit & (z > to.clip_start)
    flow[defined, 0] = (u - grid_u)[defined]
    flow[defined, 1] = (v - grid_v)[defined]
    ui, vi = np.rint(np.where(defined, u, -1)).astype(np.int64), np.rint(np.where(defined, v, -1)).astype(np.int64)
    inside = defined & (ui >= 0) & (ui < width) & (vi >= 0) & (vi < height)
    seen = np.full((height, width), np.inf)
    seen[inside] = depth_to[vi[inside], ui[inside]]
    visible = inside & (z <= seen * (1 + OCCLUSION_RELATIVE) + OCCLUSION_ABSOLUTE)
    occluded[visible] = 0
    return flow, occluded


def _local_points(raw: RasterOutput, intr: Intrinsics, cam2world: np.ndarray,
                  scene: Scene) -> Iterator[tuple[Any, np.ndarray, np.ndarray]]:
    """Per object in view: (object, its pixels' mask, float64 coordinates of those pixels' surface points in the
    object's local frame, m)."""
    world = camera_points(raw, intr) @ cam2world[:3, :3].T + cam2world[:3, 3]
    for obj in scene.objects:
        mask = raw.instance == obj.instance_id
        if mask.any():
            to_local = np.linalg.inv(obj.local2world)
            yield obj, mask, world[mask] @ to_local[:3, :3].T + to_local[:3, 3]


def object_coordinates(raw: RasterOutput, intr: Intrinsics, cam2world: np.ndarray, scene: Scene) -> np.ndarray:
    """(H, W, 3) float32 coordinates (m) of every pixel's surface point in its object's local frame (the frame
    of the mesh's vertices, before ``local2world``; NaN on the background)."""
    out = np.full(raw.instance.shape + (3,), np.nan, np.float32)
    for _, mask, local in _local_points(raw, intr, cam2world, scene):
        out[mask] = local
    return out


def nocs(raw: RasterOutput, intr: Intrinsics, cam2world: np.ndarray, scene: Scene) -> np.ndarray:
    """(H, W, 3) float32 normalized object coordinates of every pixel's surface point (background 0), from the
    float64 local coordinates (the same values as before object_coordinates existed)."""
    out = np.zeros(raw.instance.shape + (3,), np.float32)
    for obj, mask, local in _local_points(raw, intr, cam2world, scene):
        box = obj.bounds_local
        diagonal = float(np.linalg.norm(box[1] - box[0])) or 1.0
        out[mask] = (local - box.mean(axis=0)) / diagonal + 0.5
    return out
