"""Pinhole intrinsics shared by the rasterizer and the path tracer (docs/conventions.md section 2).

Pixel (u, v) has its centre at integer coordinates; (0, 0) is the centre of the top-left pixel, u grows right,
v down. ``K`` maps OpenCV camera coordinates (x right, y down, z forward, metres) to those pixel coordinates.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

DEFAULT_RESOLUTION = (512, 512)
DEFAULT_FOV = 0.691111  # rad, horizontal
DEFAULT_CLIP = (0.1, 1000.0)  # m
MAX_PIXELS = 16384 * 16384


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics: ``K`` (3x3, pixels), image size in pixels and clip range in metres."""

    K: np.ndarray
    width: int
    height: int
    clip_start: float = DEFAULT_CLIP[0]
    clip_end: float = DEFAULT_CLIP[1]

    def __post_init__(self) -> None:
        K = np.array(self.K, dtype=np.float64).reshape(3, 3)
        object.__setattr__(self, "K", K)
        object.__setattr__(self, "width", int(self.width))
        object.__setattr__(self, "height", int(self.height))
        if self.width <= 0 or self.height <= 0:
            raise InputError(f"resolution must be positive, got {self.width}x{self.height}")
        if self.width * self.height > MAX_PIXELS or max(self.width, self.height) > 16384:
            raise InputError(f"resolution {self.width}x{self.height} is absurd (at most 16384 per side)")
        if not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
            raise InputError(f"cam_K must be finite with positive fx, fy, got {K.ravel().tolist()}")
        if K[0, 1] != 0 or K[1, 0] != 0 or tuple(K[2]) != (0.0, 0.0, 1.0):
            raise InputError(f"cam_K must be [[fx,0,cx],[0,fy,cy],[0,0,1]] (no skew), got {K.ravel().tolist()}")
        if not (0 < self.clip_start < self.clip_end and math.isfinite(self.clip_end)):
            raise InputError(f"clip range must satisfy 0 < start < end < inf, got {self.clip_start}..{self.clip_end}")

    @classmethod
    def from_fov(cls, fov: float, width: int = DEFAULT_RESOLUTION[0], height: int = DEFAULT_RESOLUTION[1],
                 axis: str = "horizontal", clip_start: float = DEFAULT_CLIP[0],
                 clip_end: float = DEFAULT_CLIP[1]) -> "Intrinsics":
        """Square-pixel intrinsics from a field of view (radians) along ``axis`` and a centred principal point."""
        if not (0 < fov < math.pi):
            raise InputError(f"fov must be in (0, pi) radians, got {fov}")
        if width <= 0 or height <= 0:
            raise InputError(f"resolution must be positive, got {width}x{height}")
        size = {"horizontal": width, "vertical": height}.get(axis)
        if size is None:
            raise InputError(f"fov axis must be 'horizontal' or 'vertical', got {axis!r}")
        f = size / (2.0 * math.tan(fov / 2.0))
        K = np.array([[f, 0, (width - 1) / 2.0], [0, f, (height - 1) / 2.0], [0, 0, 1.0]])
        return cls(K, width, height, clip_start, clip_end)

    @classmethod
    def default(cls) -> "Intrinsics":
        """Default camera (docs/conventions.md section 2): 512 x 512, horizontal fov 0.691111 rad, clip 0.1..1000 m."""
        return cls.from_fov(DEFAULT_FOV)

    def resized(self, width: int | None = None, height: int | None = None) -> "Intrinsics":
        """The same camera at another resolution: K scaled so the image covers the same field of view.

        A missing side keeps the aspect ratio. Pixel centres map as u' + 0.5 = (u + 0.5) * width' / width.
        """
        if width is None and height is None:
            return self
        new_w = int(width if width is not None else round(self.width * height / self.height))  # type: ignore[operator]
        new_h = int(height if height is not None else round(self.height * new_w / self.width))
        sx, sy = new_w / self.width, new_h / self.height
        K = self.K.copy()
        K[0, 0] *= sx
        K[1, 1] *= sy
        K[0, 2] = (K[0, 2] + 0.5) * sx - 0.5
        K[1, 2] = (K[1, 2] + 0.5) * sy - 0.5
        return Intrinsics(K, new_w, new_h, self.clip_start, self.clip_end)

    def with_pixel_aspect(self, aspect_x: float, aspect_y: float = 1.0) -> "Intrinsics":
        """The camera rendered with Blender's pixel aspect ``aspect_x : aspect_y`` (its render settings) instead of
        the aspect it has now (``fy / fx``), the lens and sensor kept, as Blender does with sensor fit AUTO:
        the sensor spans the side whose aspect-scaled size is larger (``width x aspect_x`` against
        ``height x aspect_y``), then ``fy = fx x aspect_x / aspect_y``; the principal point stays.

        BlenderProc 1.0's renderers set ``pixel_aspect_x`` when they render (e.g. its SUNCG and Replica examples:
        4/3), which changes ``K`` without touching the camera's field-of-view setting."""
        if not (aspect_x > 0 and aspect_y > 0 and math.isfinite(aspect_x) and math.isfinite(aspect_y)):
            raise InputError(f"pixel aspect must be positive and finite, got {aspect_x} x {aspect_y}")
        now, new = self.K[1, 1] / self.K[0, 0], aspect_x / aspect_y

        def sensor_span(aspect: float) -> float:
            """Pixels (in fx's units) the sensor's width or height spans at pixel aspect ``aspect``."""
            return float(self.width) if self.width * aspect >= self.height else self.height / aspect

        if abs(new - now) <= 1e-12 * new:  # already this aspect (applying it twice changes nothing)
            return self
        K = self.K.copy()
        K[0, 0] = self.K[0, 0] * sensor_span(new) / sensor_span(now)
        K[1, 1] = K[0, 0] * new
        return Intrinsics(K, self.width, self.height, self.clip_start, self.clip_end)

    @property
    def resolution(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return self.width, self.height

    def pixel_rays(self) -> np.ndarray:
        """(H, W, 3) float64 camera-frame directions through every pixel centre, with z = 1."""
        u, v = np.meshgrid(np.arange(self.width, dtype=np.float64), np.arange(self.height, dtype=np.float64))
        fx, fy, cx, cy = self.K[0, 0], self.K[1, 1], self.K[0, 2], self.K[1, 2]
        return np.stack([(u - cx) / fx, (v - cy) / fy, np.ones_like(u)], axis=-1)

    def pixel_ray_lengths(self) -> np.ndarray:
        """(H, W) float32 length of every :meth:`pixel_rays` direction: the same bits as
        ``np.linalg.norm(self.pixel_rays(), axis=-1).astype(np.float32)`` (the same float64 operations in the
        same order), from one row and one column instead of an (H, W, 3) array (~10x less CPU)."""
        fx, fy, cx, cy = self.K[0, 0], self.K[1, 1], self.K[0, 2], self.K[1, 2]
        x = (np.arange(self.width, dtype=np.float64) - cx) / fx
        y = (np.arange(self.height, dtype=np.float64) - cy) / fy
        return np.sqrt(x * x + (y * y)[:, None] + 1.0).astype(np.float32)
