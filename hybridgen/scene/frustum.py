"""A pinhole camera's view frustum: whether world points lie inside it, and its eight corners.

The frustum of intrinsics ``intr`` seen from an OpenCV-axes ``cam2world`` (metres): camera depth z strictly
between the near and far clip distances, and the projection (u, v) = (fx x / z + cx, fy y / z + cy) strictly
inside the image, whose outer edges are at -0.5 and W - 0.5 (pixel centres at integers).
"""
from __future__ import annotations

from itertools import product

import numpy as np

from .intrinsics import Intrinsics


def inside_frustum(points: np.ndarray, cam2world: np.ndarray, intr: Intrinsics, near: float | None = None,
                   far: float | None = None) -> np.ndarray:
    """(N,) bool for (N, 3) world points; ``near``/``far`` (m) default to the intrinsics' clip range."""
    near = intr.clip_start if near is None else float(near)
    far = intr.clip_end if far is None else float(far)
    world2cam = np.linalg.inv(np.asarray(cam2world, dtype=np.float64))
    local = np.asarray(points, dtype=np.float64).reshape(-1, 3) @ world2cam[:3, :3].T + world2cam[:3, 3]
    z = local[:, 2]
    ahead = (z > near) & (z < far)
    safe = np.where(ahead, z, 1.0)
    u = intr.K[0, 0] * local[:, 0] / safe + intr.K[0, 2]
    v = intr.K[1, 1] * local[:, 1] / safe + intr.K[1, 2]
    return ahead & (u > -0.5) & (u < intr.width - 0.5) & (v > -0.5) & (v < intr.height - 0.5)


def frustum_corners(cam2world: np.ndarray, intr: Intrinsics, near: float | None = None,
                    far: float | None = None) -> np.ndarray:
    """(8, 3) world points (m): the corners of the frustum of ``intr`` seen from the OpenCV-axes ``cam2world``,
    on the planes at camera depth ``near`` and ``far`` (default: the intrinsics' clip range) through the image's
    outer edges (u = -0.5 / W - 0.5, v = H - 0.5 / -0.5; a principal point off centre makes it skewed).

    Corner ``i`` is the ``i``-th sign triple ``(sx, sy, sz)`` of ``itertools.product((-1, 1), repeat=3)``:
    ``sx`` -1 left / +1 right, ``sy`` -1 bottom / +1 top of the image, ``sz`` -1 near / +1 far - normalized
    device coordinates' order, as Blender's cube lists its vertices."""
    near = intr.clip_start if near is None else float(near)
    far = intr.clip_end if far is None else float(far)
    signs = np.array(list(product((-1, 1), repeat=3)), dtype=np.float64)
    u = np.where(signs[:, 0] < 0, -0.5, intr.width - 0.5)
    v = np.where(signs[:, 1] < 0, intr.height - 0.5, -0.5)
    z = np.where(signs[:, 2] < 0, near, far)
    local = np.stack([(u - intr.K[0, 2]) / intr.K[0, 0] * z, (v - intr.K[1, 2]) / intr.K[1, 1] * z, z], axis=1)
    cam2world = np.asarray(cam2world, dtype=np.float64)
    return local @ cam2world[:3, :3].T + cam2world[:3, 3]
