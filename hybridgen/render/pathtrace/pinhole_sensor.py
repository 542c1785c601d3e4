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
def sensor_base(variant: str) -> type:
    """The part every hybridgen camera sensor shares, for ``variant`` (must be the active variant): K
    (``fx``, ``fy``, ``cx``, ``cy`` in pixels) and the clip range (``near_clip``, ``far_clip`` in m) read from
    the properties, the pose as opaque rotation and origin, the film sample mapped to OpenCV camera axes
    (:meth:`camera_direction`), and rays that start on the near plane and end on the far one
    (:meth:`clipped_ray`). Subclasses implement ``sample_ray``."""
    import drjit as dr
    import mitsuba as mi

    class CameraSensorBase(mi.Sensor):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.fx, self.fy, self.cx, self.cy = (float(props.get(k)) for k in ("fx", "fy", "cx", "cy"))
            self.near, self.far = float(props.get("near_clip")), float(props.get("far_clip"))

        def set_pose_opaque(self, cam2world: np.ndarray, *extra: Any) -> None:
            """Rotation and origin of ``cam2world`` (4x4, OpenCV camera axes to world) and ``extra`` Dr.Jit
            values made opaque, so a new pose never recompiles a kernel."""
            pose = np.asarray(cam2world, dtype=np.float64)
            self.rotation = mi.Matrix3f(pose[:3, :3].tolist())
            self.origin = mi.Point3f(*pose[:3, 3].tolist())
            dr.make_opaque(self.rotation, self.origin, *extra)

        def camera_direction(self, film_sample: Any) -> Any:
            """The (unnormalized, z = 1) camera-axes direction through our pixel coordinates
            (x - 0.5, y - 0.5) of the continuous film position ``film_sample`` x film size."""
            size = self.film().size()
            x = film_sample.x * size.x - 0.5
            y = film_sample.y * size.y - 0.5
            return mi.Vector3f((x - self.cx) / self.fx, (y - self.cy) / self.fy, 1.0)

        def clipped_ray(self, start: Any, local: Any, time: Any) -> Any:
            """The world ray from ``start`` along the normalized camera-axes direction ``local``, from the
            near clip plane to the far one."""
            inv_z = dr.rcp(local.z)
            direction = self.rotation @ local
            return mi.Ray3f(start + direction * (self.near * inv_z), direction, (self.far - self.near) * inv_z,
                            time, [])

        def sample_ray_differential(self, time: Any, sample1: Any, sample2: Any, sample3: Any,
                                    active: Any = True) -> Any:
            ray, weight = self.sample_ray(time, sample1, sample2, sample3, active)
            return mi.RayDifferential3f(ray), weight

    return CameraSensorBase


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register the sensor plugin for ``variant`` (must be the active variant)."""
    import drjit as dr
    import mitsuba as mi

    class PinholeSensor(sensor_base(variant)):  # type: ignore[misc]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.set_pose(np.eye(4))

        def set_pose(self, cam2world: np.ndarray) -> None:
            self.set_pose_opaque(cam2world)

        def sample_ray(self, time: Any, sample1: Any, sample2: Any, sample3: Any, active: Any = True) -> Any:
            local = dr.normalize(self.camera_direction(sample2))
            return self.clipped_ray(self.origin, local, time), mi.Color3f(1.0)

        def to_string(self) -> str:
            return f"HybridgenPinhole[fx={self.fx}, fy={self.fy}, cx={self.cx}, cy={self.cy}]"

    mi.register_sensor(PLUGIN_NAME, lambda props: PinholeSensor(props))
