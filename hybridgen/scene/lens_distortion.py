"""Brown-Conrady lens distortion (the undistorted-to-distorted form of OpenCV, Bouguet, Kalibr and DLR CalLab) as a
resampling plan: a pinhole render large enough to be distorted into the wanted image, and for every pixel of
the distorted image the point of that render it shows.

Model, in normalized camera coordinates (x, y) = ((u - cx) / fx, (v - cy) / fy) of the undistorted pinhole
image, ``r2 = x^2 + y^2``::

    x_d = x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p2 x y + p1 (r2 + 2 x^2)
    y_d = y (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 y^2)

(``p1``/``p2`` in CalLab's order; OpenCV swaps them). The distorted pixel (u, v) = (fx x_d + cx, fy y_d + cy)
shows the undistorted point (x, y) that distorts onto it; it is found by fixed-point iteration until the worst
pixel is within ``tolerance_px`` pixels (BlenderProc's 0.15 px). Pixel centres are at integer coordinates.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .intrinsics import Intrinsics

MAX_ITERATIONS = 1000
BORDER_PX = 1
"""Pixels added on every side of the render so that spline interpolation never reaches its edge."""


@dataclass(frozen=True)
class BrownConrady:
    """Radial ``k1, k2, k3`` and decentering ``p1, p2`` coefficients (dimensionless)."""

    k1: float
    k2: float
    k3: float = 0.0
    p1: float = 0.0
    p2: float = 0.0

    def __post_init__(self) -> None:
        if all(value == 0.0 for value in (self.k1, self.k2, self.k3, self.p1, self.p2)):
            raise InputError("All given lens distortion parameters (k1, k2, k3, p1, p2) are zero.")

    def distort(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Normalized undistorted -> distorted coordinates (see the module documentation)."""
        r2 = x * x + y * y
        radial = 1 + self.k1 * r2 + self.k2 * r2 * r2 + self.k3 * r2 * r2 * r2
        return (x * radial + 2 * self.p2 * x * y + self.p1 * (r2 + 2 * x * x),
                y * radial + 2 * self.p1 * x * y + self.p2 * (r2 + 2 * y * y))


@dataclass(frozen=True)
class DistortionPlan:
    """``render``: the enlarged pinhole intrinsics to render with; ``mapping``: (2, H * W) float rows then
    columns, in ``render``'s pixels, of each distorted pixel (row-major over the ``width`` x ``height`` image)."""

    render: Intrinsics
    mapping: np.ndarray
    width: int
    height: int


def _undistort(lens: BrownConrady, x: np.ndarray, y: np.ndarray, fx: float, fy: float,
               tolerance_px: float) -> tuple[np.ndarray, np.ndarray]:
    """The undistorted normalized points that distort onto (x, y), within ``tolerance_px`` in pixels."""
    ux, uy = x.copy(), y.copy()
    for _ in range(MAX_ITERATIONS):
        dx, dy = lens.distort(ux, uy)
        residual = float(np.max(np.hypot(fx * (dx - x), fy * (dy - y)))) if x.size else 0.0
        if residual <= tolerance_px:
            return ux, uy
        if not residual < 1e9:
            break
        ux -= dx - x
        uy -= dy - y
    raise InputError("the lens distortion cannot be inverted over this image (the iteration diverges or stalls): "
                     "check k1, k2, k3, p1, p2, or use a smaller image")


def plan_distortion(intr: Intrinsics, lens: BrownConrady, tolerance_px: float = 0.15) -> DistortionPlan:
    """The render and mapping that give ``intr``'s image under ``lens`` (see the module documentation). The
    render keeps fx, fy and the clip range; its size covers every needed point plus :data:`BORDER_PX` on each
    side, its principal point moves with it."""
    fx, fy, cx, cy = intr.K[0, 0], intr.K[1, 1], intr.K[0, 2], intr.K[1, 2]
    rows, cols = np.divmod(np.arange(intr.width * intr.height), intr.width)
    x, y = _undistort(lens, (cols - cx) / fx, (rows - cy) / fy, fx, fy, tolerance_px)
    u, v = fx * x + cx, fy * y + cy
    first_col, first_row = np.floor(u.min()), np.floor(v.min())
    width = int(np.ceil(u.max()) - first_col + 1 + 2 * BORDER_PX)
    height = int(np.ceil(v.max()) - first_row + 1 + 2 * BORDER_PX)
    shift_col, shift_row = BORDER_PX - first_col, BORDER_PX - first_row
    K = intr.K.copy()
    K[0, 2], K[1, 2] = cx + shift_col, cy + shift_row
    render = Intrinsics(K, width, height, intr.clip_start, intr.clip_end)
    return DistortionPlan(render, np.vstack([v + shift_row, u + shift_col]), intr.width, intr.height)
