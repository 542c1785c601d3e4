"""Blender's camera parameters and the pinhole K they stand for, as BlenderProc converts between them
(its ``get_intrinsics_as_K_matrix`` / ``set_intrinsics_from_K_matrix``).

Blender describes a camera by its focal length ``lens`` (mm) on a sensor (``sensor_width`` x ``sensor_height``
mm, 36 x 24 by default, fit ``AUTO``: the sensor width spans the image side whose pixel-aspect-scaled size is
larger), the render resolution (px), the pixel aspect (``pixel_aspect_x``, ``pixel_aspect_y``), the lens shift
(``shift_x``, ``shift_y``, in units of that spanned side) and the clip range (m). BlenderProc's pixel
convention puts the centred principal point at ``((W - 1) / 2, (H - 1) / 2)``, hybridgen's too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..scene.camera import Intrinsics

DEFAULT_FOV = 0.691111
"""BlenderProc's default horizontal field of view (rad): Blender's 50 mm lens on its 36 mm sensor."""


@dataclass
class BlenderCamera:
    """The scene camera's Blender parameters (see the module documentation for units)."""

    lens: float = 18.0 / math.tan(DEFAULT_FOV / 2)
    sensor_width: float = 36.0
    sensor_height: float = 24.0
    sensor_fit: str = "AUTO"
    lens_unit: str = "FOV"
    resolution_x: int = 512
    resolution_y: int = 512
    pixel_aspect_x: float = 1.0
    pixel_aspect_y: float = 1.0
    shift_x: float = 0.0
    shift_y: float = 0.0
    clip_start: float = 0.1
    clip_end: float = 1000.0

    def sensor_size(self) -> float:
        """The sensor side the lens is measured against (mm)."""
        return self.sensor_height if self.sensor_fit == "VERTICAL" else self.sensor_width

    def view_factor(self) -> float:
        """Pixels the sensor size spans (Blender's sensor fit)."""
        fit = self.sensor_fit
        if fit == "AUTO":
            wide = self.pixel_aspect_x * self.resolution_x >= self.pixel_aspect_y * self.resolution_y
            fit = "HORIZONTAL" if wide else "VERTICAL"
        if fit == "HORIZONTAL":
            return float(self.resolution_x)
        return self.pixel_aspect_y / self.pixel_aspect_x * self.resolution_y

    def K(self) -> np.ndarray:  # noqa: N802 - the matrix's name
        """The 3x3 pinhole matrix (px)."""
        view = self.view_factor()
        ratio = self.pixel_aspect_y / self.pixel_aspect_x
        fx = self.lens / self.sensor_size() * view
        cx = (self.resolution_x - 1) / 2 - self.shift_x * view
        cy = (self.resolution_y - 1) / 2 + self.shift_y * view / ratio
        return np.array([[fx, 0.0, cx], [0.0, fx / ratio, cy], [0.0, 0.0, 1.0]])

    def set_K(self, K: np.ndarray, width: int, height: int) -> None:  # noqa: N802
        """Set lens, resolution, pixel aspect and shift so that :meth:`K` is ``K`` (fx != fy becomes a pixel
        aspect, as in Blender)."""
        K = np.asarray(K, dtype=np.float64).reshape(3, 3)
        if abs(K[0, 1]) > 1e-7:
            raise InputError(f"skew is not supported by Blender and so not by BlenderProc: K[0][1] = {K[0, 1]}")
        fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
        if not (fx > 0 and fy > 0):
            raise InputError(f"K needs positive focal lengths, got fx={fx}, fy={fy}")
        self.pixel_aspect_x, self.pixel_aspect_y = (fy / fx, 1.0) if fx < fy else (1.0, fx / fy)
        self.resolution_x, self.resolution_y = int(width), int(height)
        view = self.view_factor()
        self.lens = fx * self.sensor_size() / view
        self.shift_x = (cx - (width - 1) / 2) / -view
        self.shift_y = (cy - (height - 1) / 2) / view * (self.pixel_aspect_y / self.pixel_aspect_x)

    def set_fov(self, angle: float) -> None:
        """Blender's ``camera.angle`` (rad): the lens whose field of view over the sensor size is ``angle``."""
        if not 0 < angle < math.pi:
            raise InputError(f"field of view must be in (0, pi) rad, got {angle}")
        self.lens = self.sensor_size() / 2 / math.tan(angle / 2)

    def fov(self) -> tuple[float, float]:
        """(horizontal, vertical) field of view in rad, as BlenderProc's ``get_fov`` computes them from K."""
        K = self.K()
        return (2 * math.atan(self.resolution_x / 2 / K[0, 0]), 2 * math.atan(self.resolution_y / 2 / K[1, 1]))

    def intrinsics(self) -> Intrinsics:
        """hybridgen's intrinsics of this camera."""
        return Intrinsics(self.K(), self.resolution_x, self.resolution_y, self.clip_start, self.clip_end)
