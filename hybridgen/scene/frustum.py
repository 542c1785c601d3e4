"""Whether world points lie inside a pinhole camera's view frustum.

The frustum of intrinsics ``intr`` seen from an OpenCV-axes ``cam2world`` (metres): camera depth z strictly
between the near and far clip distances, and the projection (u, v) = (fx x / z + cx, fy y / z + cy) strictly
inside the image, whose outer edges are at -0.5 and W - 0.5 (pixel centres at integers).
"""
from __future__ import annotations

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
