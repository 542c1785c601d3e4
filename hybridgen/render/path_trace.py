"""The path-trace view: one Mitsuba 3 scene built from the scene model, rendered from any keypoint.

The scene (geometry, BSDFs, lights, integrator) is loaded once; a keypoint only changes the sensor's
``to_world`` through ``mi.traverse``, which rebuilds nothing. The sensor is made from the same K and clip
range as the raster view, with a one-pixel box filter: color pixel (u, v) integrates the pixel footprint
``[u - 0.5, u + 0.5] x [v - 0.5, v + 0.5]`` around the centre where the label sample (u, v) is taken.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..scene.camera import Intrinsics
from ..scene.scene import Scene
from .mitsuba_scene import scene_dict
from . import pinhole_sensor
from .mitsuba_variant import activate, choose_variant, is_jit

OPENCV_TO_MITSUBA = np.diag([-1.0, -1.0, 1.0, 1.0])
"""Mitsuba's camera looks along +z with +y up and +x to the image's left; OpenCV's x is right, y down."""


@dataclass(frozen=True)
class PathTraceSettings:
    """Integrator settings in BlenderProc's terms.

    Bounces count as in Cycles: ``max_bounces`` 0 is direct light only. Mitsuba's ``path`` integrator counts
    path segments, so ``max_depth = max_bounces + 2`` and Russian roulette starts at
    ``rr_depth = min(min_bounces, max_bounces) + 2``. Mitsuba has a single depth limit for all
    lobes, so ``glossy_bounces`` can only be honoured when it is not smaller than ``max_bounces``; a
    smaller value is rejected rather than silently ignored.
    """

    samples: int = 64
    min_bounces: int = 1
    max_bounces: int = 8
    glossy_bounces: int | None = None

    def __post_init__(self) -> None:
        if self.samples < 1:
            raise InputError(f"samples must be >= 1, got {self.samples}")
        if self.min_bounces < 0 or self.max_bounces < 0:
            raise InputError("min_bounces and max_bounces must be >= 0")
        if self.glossy_bounces is not None and self.glossy_bounces < self.max_bounces:
            raise InputError(f"glossy_bounces ({self.glossy_bounces}) < max_bounces ({self.max_bounces}) cannot "
                             "be honoured: Mitsuba's path tracer has one depth limit for every lobe")

    def integrator(self) -> dict[str, Any]:
        rr_depth = min(self.min_bounces, self.max_bounces) + 2  # no roulette needed past the last bounce
        return {"type": "path", "max_depth": self.max_bounces + 2, "rr_depth": rr_depth,
                "hide_emitters": False}


def sensor_dict(intr: Intrinsics, cam2world: np.ndarray, variant: str) -> dict[str, Any]:
    """The sensor of ``intr`` with a one-pixel box filter.

    JIT variants use :mod:`hybridgen.render.pinhole_sensor` (any K); ``scalar_rgb``, where a Python sensor
    would run per sample, uses Mitsuba's ``perspective`` sensor, which needs square pixels.
    """
    import mitsuba as mi

    film = {"type": "hdrfilm", "width": intr.width, "height": intr.height, "pixel_format": "rgb",
            "rfilter": {"type": "box"}, "sample_border": False}
    fx, fy, cx, cy = intr.K[0, 0], intr.K[1, 1], intr.K[0, 2], intr.K[1, 2]
    common = {"near_clip": intr.clip_start, "far_clip": intr.clip_end, "film": film,
              "sampler": {"type": "independent"}}
    if is_jit(variant):
        pinhole_sensor.register(variant)
        return {"type": pinhole_sensor.PLUGIN_NAME, "fx": fx, "fy": fy, "cx": cx, "cy": cy, **common}
    if not math.isclose(fx, fy, rel_tol=1e-9):
        raise InputError(f"fx != fy ({fx} vs {fy}) needs a JIT Mitsuba variant (llvm_ad_rgb or cuda_ad_rgb); "
                         "scalar_rgb's perspective sensor has square pixels (install libllvm19)")
    return {
        "type": "perspective",
        "fov_axis": "x",
        "fov": math.degrees(2 * math.atan(intr.width / (2 * fx))),
        # Mitsuba measures the principal point offset in film widths/heights, positive towards -u / -v.
        "principal_point_offset_x": -(cx - (intr.width - 1) / 2) / intr.width,
        "principal_point_offset_y": -(cy - (intr.height - 1) / 2) / intr.height,
        "to_world": mi.ScalarTransform4f((np.asarray(cam2world) @ OPENCV_TO_MITSUBA).tolist()),
        **common,
    }


class PathTraceView:
    """Renders linear RGB (float32, H x W x 3, top-down) of ``scene`` for any keypoint of its camera."""

    def __init__(self, scene: Scene, settings: PathTraceSettings | None = None, *, variant: str | None = None,
                 integrator: dict[str, Any] | None = None) -> None:
        import mitsuba as mi

        self.settings = settings or PathTraceSettings()
        self.variant = choose_variant(variant)
        activate(self.variant)
        self.intrinsics = scene.camera.intrinsics
        description = scene_dict(scene)
        description["integrator"] = integrator or self.settings.integrator()
        first = scene.camera.keypoints[0] if scene.camera.keypoints else np.eye(4)
        description["sensor"] = sensor_dict(self.intrinsics, first, self.variant)
        try:
            self.mi_scene = mi.load_dict(description)
        except RuntimeError as exc:
            raise InputError(f"Mitsuba could not build the scene: {str(exc).splitlines()[-1]}") from None
        self.sensor = self.mi_scene.sensors()[0]
        self._sensor_params = None if is_jit(self.variant) else mi.traverse(self.sensor)

    def set_pose(self, cam2world: np.ndarray) -> None:
        """Move the sensor to an OpenCV-axes ``cam2world`` (nothing else is rebuilt)."""
        import mitsuba as mi

        if self._sensor_params is None:  # the pinhole sensor holds its pose as an opaque variable
            self.sensor.set_pose(cam2world)
            return
        self._sensor_params["to_world"] = mi.ScalarTransform4f((np.asarray(cam2world) @ OPENCV_TO_MITSUBA).tolist())
        self._sensor_params.update()

    def render(self, cam2world: np.ndarray, seed: int, spp: int | None = None) -> np.ndarray:
        """Linear RGB of one keypoint; ``seed`` fixes the sample pattern (same seed -> same bytes)."""
        import mitsuba as mi

        self.set_pose(cam2world)
        image = mi.render(self.mi_scene, sensor=self.sensor, spp=spp or self.settings.samples, seed=int(seed))
        return np.array(image, dtype=np.float32)[..., :3]


def mitsuba_pixel_centre_depth(view: PathTraceView, cam2world: np.ndarray) -> np.ndarray:
    """Camera-z depth (m, float64, ``inf`` for misses) of the first surface Mitsuba's own sensor and ray
    tracer find through every pixel centre - an independent check of the raster labels' alignment."""
    import drjit as dr
    import mitsuba as mi

    view.set_pose(cam2world)
    intr = view.intrinsics
    u, v = np.meshgrid(np.arange(intr.width) + 0.5, np.arange(intr.height) + 0.5)
    film_pos = np.stack([u.ravel() / intr.width, v.ravel() / intr.height], axis=1)
    origin, forward = np.asarray(cam2world)[:3, 3], np.asarray(cam2world)[:3, 2]
    if dr.is_jit_v(mi.Float):
        ray, _ = view.sensor.sample_ray(0.0, 0.5, mi.Point2f(film_pos[:, 0], film_pos[:, 1]), mi.Point2f(0.5, 0.5))
        si = view.mi_scene.ray_intersect(ray)
        points = np.stack([np.array(c, dtype=np.float64) for c in (si.p.x, si.p.y, si.p.z)], axis=1)
        valid = np.array(si.is_valid(), dtype=bool)
    else:
        points = np.zeros((len(film_pos), 3))
        valid = np.zeros(len(film_pos), dtype=bool)
        for i, (x, y) in enumerate(film_pos):
            ray, _ = view.sensor.sample_ray(0.0, 0.5, mi.Point2f(x, y), mi.Point2f(0.5, 0.5))
            si = view.mi_scene.ray_intersect(ray)
            valid[i] = bool(si.is_valid())
            points[i] = [si.p.x, si.p.y, si.p.z]
    depth = np.where(valid, (points - origin) @ forward, np.inf)
    return depth.reshape(intr.height, intr.width)
