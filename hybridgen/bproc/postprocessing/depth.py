"""Depth <-> distance conversions and channel trimming of ``bproc.postprocessing``.

Depth is the z coordinate of a pixel's surface point in the camera frame (metres, along the optical axis);
distance is that point's Euclidean distance from the camera centre (metres). Pixel (u, v) is centred at integer
coordinates (column u, row v), as in docs/conventions.md section 2, and its ray through the camera with
intrinsics K is ``((u - cx) / fx, (v - cy) / fy, 1)``.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from .scene_state import camera_K

__all__ = ["depth2dist", "dist2depth", "trim_redundant_channels"]


def trim_redundant_channels(image: Any) -> Any:
    """The first channel of three-channel images (BlenderProc's depth and distance arrive as H x W x 3 copies):
    an H x W x 3 array becomes H x W; a list is trimmed per element (a list back); an array of more than three
    dimensions per first-axis element (an array back). Anything else is returned as it is. The channels are
    not checked for equality."""
    if isinstance(image, list):
        return [trim_redundant_channels(element) for element in image]
    if hasattr(image, "shape") and len(image.shape) > 3:
        return np.array([trim_redundant_channels(element) for element in image])
    if hasattr(image, "shape") and len(image.shape) == 3 and image.shape[2] == 3:
        return image[:, :, 0]
    return image


def is_image_list(images: Any) -> bool:
    """Whether ``images`` is a list or a stack (more than two axes) of H x W images."""
    return isinstance(images, list) or (hasattr(images, "shape") and len(images.shape) > 2)


def _ray_length_terms(K: np.ndarray, xs: Any, ys: Any) -> tuple[float, np.ndarray]:
    """``(fx, sqrt(dx^2 + (dy * fx / fy)^2 + fx^2))`` for pixel offsets from the principal point: the ratio of
    distance to depth is the second over the first (BlenderProc's formula, which assumes fx == fy, extended
    to fx != fy)."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    dx = np.abs(xs - cx)
    dy = np.abs(ys - cy) if fx == fy else np.abs(ys - cy) * (fx / fy)
    return fx, np.sqrt(dx ** 2 + dy ** 2 + fx ** 2)


def dist2depth(dist: Any, points_2d: Optional[np.ndarray] = None, *, K: Optional[Any] = None) -> Any:
    """Depth (m) from distance (m): one H x W image (H x W x 3 copies are trimmed first), a list or a stack of
    them (a list back), or a 1-D array of distances at the pixels ``points_2d`` (N x 2 columns u, v).

    ``K`` (hybridgen's addition) defaults to the current camera's intrinsics, as BlenderProc reads them.
    """
    dist = trim_redundant_channels(dist)
    if is_image_list(dist):
        return [dist2depth(image, K=K) for image in dist]
    if points_2d is None:
        xs, ys = np.meshgrid(np.arange(dist.shape[1]), np.arange(dist.shape[0]))
    else:
        xs, ys = points_2d[:, 0], points_2d[:, 1]
    fx, ray = _ray_length_terms(camera_K(K), xs, ys)
    return dist * fx / ray


def depth2dist(depth: Any, *, K: Optional[Any] = None) -> Any:
    """Distance (m) from depth (m): one H x W image (H x W x 3 copies are trimmed first), or a list or stack of
    them (a list back). ``K`` (hybridgen's addition) defaults to the current camera's intrinsics."""
    depth = trim_redundant_channels(depth)
    if is_image_list(depth):
        return [depth2dist(image, K=K) for image in depth]
    xs, ys = np.meshgrid(np.arange(depth.shape[1]), np.arange(depth.shape[0]))
    fx, ray = _ray_length_terms(camera_K(K), xs, ys)
    return depth * ray / fx
