"""A Mitsuba sensor that projects with a full pinhole K (fx != fy, any principal point).

Mitsuba's built-in ``perspective`` sensor assumes square pixels. This one generates, for a film position
(x, y) in continuous film coordinates (pixel u spans [u, u + 1)), the ray through our pixel coordinates
(x - 0.5, y - 0.5) of K, in OpenCV camera axes, starting on the near clip plane and ending on the far
one, as the rasterizer clips. The pose is an opaque Dr.Jit variable, so moving the camera never
recompiles a kernel. Registered per variant as ``hybridgen_pinhole``; efficient in the JIT variants
(the Python code is traced once into the kernel).
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

PLUGIN_NAME = "hybridgen_pinhole"


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register the sensor plugin for ``variant`` (must be the active variant)."""
    import drjit as dr
    import mitsuba as mi

    class PinholeSensor(mi.Sensor):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.fx, self.fy, self.cx, self.cy = (float(props.get(k)) for k in ("fx", "fy", "cx", "cy"))
            self.near, self.far = float(props.get("near_clip")), float(props.get("far_clip"))
            self.set_pose(np.eye(4))

        def set_pose(self, cam2world: np.ndarray) -> None:
            pose = np.asarray(cam2world, dtype=np.float64)
            self.rotation = mi.Matrix3f(pose[:3, :3].tolist())
            self.origin = mi.Point3f(*pose[:3, 3].tolist())
            dr.make_opaque(self.rotation, self.origin)

        def sample_ray(self, time: Any, sample1: Any, sample2: Any, sample3: Any, active: Any = True) -> Any:
            size = self.film().size()
            x = sample2.x * size.x - 0.5
            y = sample2.y * size.y - 0.5
            local = dr.normalize(mi.Vector3f((x - self.cx) / self.fx, (y - self.cy) / self.fy, 1.0))
            inv_z = dr.rcp(local.z)
            direction = self.rotation @ local
            ray = mi.Ray3f(self.origin + direction * (self.near * inv_z), direction,
                           (self.far - self.near) * inv_z, time, [])
            return ray, mi.Color3f(1.0)

        def sample_ray_differential(self, time: Any, sample1: Any, sample2: Any, sample3: Any,
                                    active: Any = True) -> Any:
            ray, weight = self.sample_ray(time, sample1, sample2, sample3, active)
            return mi.RayDifferential3f(ray), weight

        def to_string(self) -> str:
            return f"HybridgenPinhole[fx={self.fx}, fy={self.fy}, cx={self.cx}, cy={self.cy}]"

    mi.register_sensor(PLUGIN_NAME, lambda props: PinholeSensor(props))
