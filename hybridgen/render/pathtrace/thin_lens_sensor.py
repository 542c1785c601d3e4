"""A Mitsuba sensor with a thin lens (depth of field) and a full pinhole K, as Cycles models Blender's camera.

For film position (x, y) (pixel u spans [u, u + 1)) the pinhole ray of our pixel coordinates (x - 0.5, y - 0.5)
reaches the point ``F`` at depth ``focus_distance`` (camera z, m); the ray starts at a point ``L`` of the
aperture disk (radius ``aperture_radius`` m in the camera's x-y plane, drawn uniformly from the aperture
sample) and goes through ``F`` (:mod:`hybridgen.scene.depth_of_field` gives both from Blender's f-stop and
focus). It starts and ends on the near and far clip planes, as the pinhole sensor's rays do. With a
``focus point`` the focus distance is that point's depth along the view axis, recomputed on every
:meth:`set_pose` (Blender's focus object). Registered per JIT variant as ``hybridgen_thinlens``; the pose and the
focus distance are opaque Dr.Jit variables, so moving the camera never recompiles a kernel.

Labels are not affected: the rasterizer stays a pinhole camera, exact at pixel centres, so a label pixel is
the surface at the centre of the aperture (the in-focus ray), not a blur of what the color pixel shows.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from . import pinhole_sensor

PLUGIN_NAME = "hybridgen_thinlens"


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register the sensor plugin for ``variant`` (must be the active variant)."""
    import drjit as dr
    import mitsuba as mi

    def _decorrelated(aperture: Any, film: Any) -> Any:
        """The aperture sample shifted (mod 1) by a hash of the film sample: the sample generator's dimension
        pairs are correlated (hybridgen's ``ldsampler``: -0.24 between film x and aperture x over one pixel's
        256 samples), which left a 20 % dip in the middle of a defocused line's image; shifted, the aperture
        points are independent of the film position (the blur converges to the thin-lens disk)."""
        bits_x = dr.reinterpret_array(mi.UInt32, film.x)
        bits_y = dr.reinterpret_array(mi.UInt32, film.y)
        shift_x = mi.sample_tea_float32(bits_x, bits_y, 4)
        shift_y = mi.sample_tea_float32(bits_y, bits_x ^ 0x9E3779B9, 4)
        x, y = aperture.x + shift_x, aperture.y + shift_y
        return mi.Point2f(x - dr.floor(x), y - dr.floor(y))

    class ThinLensSensor(pinhole_sensor.sensor_base(variant)):  # type: ignore[misc]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.radius = float(props.get("aperture_radius"))
            self.fixed_focus = float(props.get("focus_distance"))
            self.focus_point = (np.array([float(props.get(f"focus_{axis}")) for axis in "xyz"])
                                if "focus_x" in props else None)
            self.m_needs_sample_3 = True  # the aperture sample
            self.set_pose(np.eye(4))

        def set_pose(self, cam2world: np.ndarray) -> None:
            pose = np.asarray(cam2world, dtype=np.float64)
            focus = self.fixed_focus
            if self.focus_point is not None:  # Blender's focus object: its depth along the view axis
                focus = max(abs(float(pose[:3, 2] @ (pose[:3, 3] - self.focus_point))), 1e-6)
            self.focus = mi.Float(focus)
            self.set_pose_opaque(pose, self.focus)

        def sample_ray(self, time: Any, sample1: Any, sample2: Any, sample3: Any, active: Any = True) -> Any:
            focus = self.camera_direction(sample2) * self.focus
            lens = mi.warp.square_to_uniform_disk_concentric(_decorrelated(sample3, sample2)) * self.radius
            local = dr.normalize(focus - mi.Vector3f(lens.x, lens.y, 0.0))
            start = self.origin + self.rotation @ mi.Vector3f(lens.x, lens.y, 0.0)
            return self.clipped_ray(start, local, time), mi.Color3f(1.0)

        def to_string(self) -> str:
            return f"HybridgenThinLens[fx={self.fx}, fy={self.fy}, aperture_radius={self.radius}]"

    mi.register_sensor(PLUGIN_NAME, lambda props: ThinLensSensor(props))


def sensor(intr: Any, cam2world: np.ndarray, variant: str, depth_of_field: Any, common: dict[str, Any]
           ) -> dict[str, Any]:
    """The ``mi.load_dict`` entry of a thin-lens sensor for ``intr`` (:class:`~hybridgen.scene.camera.Intrinsics`)
    and ``depth_of_field`` (:class:`~hybridgen.scene.depth_of_field.DepthOfField`); ``common``: film, sampler,
    clip range."""
    register(variant)
    entry = {"type": PLUGIN_NAME, "fx": intr.K[0, 0], "fy": intr.K[1, 1], "cx": intr.K[0, 2], "cy": intr.K[1, 2],
             "aperture_radius": depth_of_field.aperture_radius(intr),
             "focus_distance": depth_of_field.distance_at(cam2world), **common}
    if depth_of_field.focus_point is not None:
        entry.update({f"focus_{axis}": float(value) for axis, value in zip("xyz", depth_of_field.focus_point)})
    return entry
