"""A thin-lens camera's depth of field, as Blender (Cycles) defines it (BlenderProc's ``depth_of_field``).

- Aperture radius (m) = focal length / (2 f-stop), the focal length in metres as Blender derives it from the
  pinhole K: the 36 mm sensor width spans the larger image side (``sensor_fit`` AUTO, square pixels), so
  ``focal_length = fx * 0.036 / max(width, height)``. Cycles: ``aperturesize = lens * 1e-3 / (2 * fstop)``.
- Focus distance (m) along the camera's view axis: either fixed (``focus_distance``) or that of a world point
  (the focus object's origin): ``|dot(view axis, camera origin - point)|``, recomputed per keypoint, as Cycles
  does for ``dof.focus_object``.

A camera ray through pixel (u, v) starts at a point of the aperture disk (radius above, in the camera's x-y
plane) and passes through the point the pinhole ray of (u, v) reaches at depth ``focus_distance``. A point at
depth ``z`` is thus spread over a disk of diameter ``2 fx R |z - s| / (z s)`` pixels (``R`` the aperture radius,
``s`` the focus distance): the circle of confusion (:meth:`DepthOfField.blur_diameter_px`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .intrinsics import Intrinsics

SENSOR_WIDTH_M = 0.036
"""Blender's default sensor width (36 mm), spanning the larger image side."""


@dataclass(frozen=True)
class DepthOfField:
    """``fstop`` (Blender's ``aperture_fstop``) and the focus: ``focus_distance`` (m) or ``focus_point`` (world)."""

    fstop: float = 2.4
    focus_distance: float | None = None
    focus_point: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if not (self.fstop > 0 and np.isfinite(self.fstop)):
            raise InputError(f"fstop must be a positive number, got {self.fstop}")
        if (self.focus_distance is None) == (self.focus_point is None):
            raise InputError("depth of field needs a focus distance or a focus point (one of them)")
        if self.focus_distance is not None and not (self.focus_distance > 0 and np.isfinite(self.focus_distance)):
            raise InputError(f"focus distance must be a positive finite number (m), got {self.focus_distance}")

    @staticmethod
    def focal_length(intr: Intrinsics) -> float:
        """The lens focal length (m) Blender gives a camera of these intrinsics (36 mm sensor, fit AUTO)."""
        return float(intr.K[0, 0]) * SENSOR_WIDTH_M / max(intr.width, intr.height)

    def aperture_radius(self, intr: Intrinsics) -> float:
        """Radius of the aperture disk (m): focal length / (2 f-stop)."""
        return self.focal_length(intr) / (2.0 * self.fstop)

    def distance_at(self, cam2world: np.ndarray) -> float:
        """Focus distance (m) along the view axis of the OpenCV-axes pose ``cam2world``."""
        if self.focus_point is None:
            return float(self.focus_distance)  # type: ignore[arg-type]
        pose = np.asarray(cam2world, dtype=np.float64)
        distance = abs(float(pose[:3, 2] @ (pose[:3, 3] - np.asarray(self.focus_point, dtype=np.float64))))
        return max(distance, 1e-6)  # a focus point in the camera's own plane: focused as close as it gets

    def blur_diameter_px(self, intr: Intrinsics, depth: float, focus_distance: float) -> float:
        """Circle of confusion (px, along x) of a point at camera depth ``depth`` (m) when focused at
        ``focus_distance`` (m)."""
        radius = self.aperture_radius(intr)
        return 2.0 * float(intr.K[0, 0]) * radius * abs(depth - focus_distance) / (depth * focus_distance)
