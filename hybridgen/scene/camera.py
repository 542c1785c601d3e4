"""The pinhole camera shared by the rasterizer and the path tracer (docs/conventions.md section 2).

Pixel (u, v) has its centre at integer coordinates; (0, 0) is the centre of the top-left pixel,
u grows right, v down. Poses (keypoints) are ``cam2world`` 4x4 matrices in OpenCV camera axes
(x right, y down, z forward), metres.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from .intrinsics import DEFAULT_CLIP, DEFAULT_FOV, DEFAULT_RESOLUTION, MAX_PIXELS, Intrinsics

if TYPE_CHECKING:
    from .depth_of_field import DepthOfField

__all__ = ["Camera", "Intrinsics", "DEFAULT_CLIP", "DEFAULT_FOV", "DEFAULT_RESOLUTION", "MAX_PIXELS"]

@dataclass
class Camera:
    """Intrinsics plus an ordered list of keypoints (OpenCV-axes ``cam2world`` 4x4, metres)."""

    intrinsics: Intrinsics = field(default_factory=Intrinsics.default)
    keypoints: list[np.ndarray] = field(default_factory=list)
    intrinsics_per_keypoint: list[Intrinsics] | None = None
    """One Intrinsics per keypoint where they differ between keypoints (BOP scene replication); renderers give
    ``intrinsics`` each keypoint's before rendering it (:func:`hybridgen.scene.object_keyframes.apply_keypoint`)."""
    depth_of_field: "DepthOfField | None" = None
    """A thin lens (color only; labels stay pinhole, exact at pixel centres); None: a pinhole camera."""

    def add_keypoint(self, cam2world: np.ndarray) -> int:
        """Append a pose (OpenCV axes) and return its keypoint index."""
        pose = np.array(cam2world, dtype=np.float64)
        if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
            raise InputError(f"cam2world must be a finite 4x4 matrix, got shape {pose.shape}")
        rot = pose[:3, :3]
        if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-5) or np.linalg.det(rot) < 0:
            raise InputError("cam2world rotation must be orthonormal and right-handed (no scale, no mirror)")
        if not np.allclose(pose[3], [0, 0, 0, 1]):
            raise InputError("cam2world last row must be [0, 0, 0, 1]")
        self.keypoints.append(pose)
        return len(self.keypoints) - 1

    def world2cam(self, index: int) -> np.ndarray:
        """Inverse of keypoint ``index``: world -> OpenCV camera coordinates."""
        pose = self.keypoints[index]
        inv = np.eye(4)
        inv[:3, :3] = pose[:3, :3].T
        inv[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
        return inv

    def __len__(self) -> int:
        return len(self.keypoints)
