"""Named label passes (docs/conventions.md section 3): dtype, per-keypoint shape, background, definition.

A pass is computed from the raster view's per-keypoint :class:`RasterOutput`. Writers consume passes by
name; adding a pass means adding one entry here.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass
class RasterOutput:
    """What one label draw of one keypoint reads back, all top-down (row 0 = image row v = 0).

    ``normal_depth`` is (H, W, 4) float32: unit normal xyz (camera or world axes) and camera z (metres);
    ``instance`` is (H, W) uint32, 0 where no surface was hit.
    """

    normal_depth: np.ndarray
    instance: np.ndarray
    ray_lengths: np.ndarray  # (H, W) float32 |(x/z, y/z, 1)| per pixel centre
    category_lut: np.ndarray  # int32 lookup: instance id -> category_id (0 -> 0)
    depth_background: float

    @property
    def hit(self) -> np.ndarray:
        return self.instance != 0


@dataclass(frozen=True)
class PassSpec:
    """A label pass: its key in outputs, element dtype, per-keypoint shape suffix and definition."""

    key: str
    dtype: str
    channels: int  # 0: (H, W); k: (H, W, k)
    doc: str
    compute: Callable[[RasterOutput], np.ndarray]


def _depth(out: RasterOutput) -> np.ndarray:
    depth = np.array(out.normal_depth[..., 3], dtype=np.float32)
    depth[~out.hit] = out.depth_background
    return depth


def _distance(out: RasterOutput) -> np.ndarray:
    dist = out.normal_depth[..., 3] * out.ray_lengths
    dist[~out.hit] = out.depth_background
    return dist.astype(np.float32, copy=False)


def _normals(out: RasterOutput) -> np.ndarray:
    return out.normal_depth[..., :3]  # a view: writers copy it (off the render thread) when they store it


def _instance(out: RasterOutput) -> np.ndarray:
    return out.instance.astype(np.int32)


def _category(out: RasterOutput) -> np.ndarray:
    return out.category_lut[out.instance]


PASSES: dict[str, PassSpec] = {
    spec.key: spec
    for spec in (
        PassSpec("depth", "float32", 0, "distance along the optical axis (camera z), metres; background "
                 "= depth_background (inf by default)", _depth),
        PassSpec("distance", "float32", 0, "Euclidean distance from the camera centre, metres; background "
                 "= depth_background", _distance),
        PassSpec("normals", "float32", 3, "unit surface normal facing the camera, xyz in [-1, 1], camera "
                 "(OpenCV) or world axes; background (0, 0, 0)", _normals),
        PassSpec("instance_segmaps", "int32", 0, "instance id 1..N, stable across keypoints; background 0",
                 _instance),
        PassSpec("category_id_segmaps", "int32", 0, "the object's category_id; background 0", _category),
    )
}
"""Every label pass the raster view can produce, by output key."""
