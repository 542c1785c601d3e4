"""OpenGL projection from the shared pinhole K (docs/conventions.md section 2).

The camera frame is OpenCV's (z forward, y down). With this matrix the centre of pixel (u, v) maps to
NDC ``(2(u + 0.5)/W - 1, 2(v + 0.5)/H - 1)``, which OpenGL rasterizes at window position (u + 0.5, v + 0.5):
every label sample lies exactly on its pixel centre. There is no y flip, so framebuffer row 0 (OpenGL's
bottom row) holds image row v = 0; reading rows in OpenGL order gives a top-down image directly. The
handedness is mirrored by this, so front faces wind clockwise on screen.
"""
from __future__ import annotations

import numpy as np


def projection_from_K(K: np.ndarray, width: int, height: int, near: float, far: float) -> np.ndarray:
    """4x4 float64 projection (row-major, column vectors) mapping OpenCV camera coordinates to clip space."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    return np.array([
        [2 * fx / width, 0.0, 2 * (cx + 0.5) / width - 1.0, 0.0],
        [0.0, 2 * fy / height, 2 * (cy + 0.5) / height - 1.0, 0.0],
        [0.0, 0.0, (far + near) / (far - near), -2 * far * near / (far - near)],
        [0.0, 0.0, 1.0, 0.0],
    ])


def near_plane_corner_distance(K: np.ndarray, width: int, height: int, near: float) -> float:
    """Largest distance (metres) from the camera centre to a point of the near clip plane inside the image."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    xs = np.array([-0.5 - cx, width - 0.5 - cx]) / fx
    ys = np.array([-0.5 - cy, height - 0.5 - cy]) / fy
    return float(near * np.sqrt(1.0 + np.max(xs ** 2) + np.max(ys ** 2)))
