"""Rigid poses of objects relative to a camera, as dataset formats (BOP) store them: a rotation without the
object's scale and a translation, both in OpenCV camera axes (x right, y down, z forward)."""
from __future__ import annotations

import numpy as np

from ..errors import InputError


def rigid_rotation(linear: np.ndarray, name: str) -> np.ndarray:
    """The rotation of a 3x3 rotation-times-scale matrix (polar decomposition); mirrors are errors naming
    object ``name``."""
    u, s, vt = np.linalg.svd(linear)
    if s.min() <= 0 or np.linalg.det(u @ vt) < 0:
        raise InputError(f"object '{name}' has a mirrored or degenerate pose: BOP poses are rotations")
    return u @ vt


def model_to_camera(world2cam: np.ndarray, local2world: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``(R 3x3, t 3 in metres)`` of the object's local frame in the camera's (OpenCV axes): ``R`` is the
    rotation only (an object scale is not part of it), ``t`` the local origin in camera coordinates."""
    obj2cam = world2cam @ local2world
    return rigid_rotation(obj2cam[:3, :3], name), obj2cam[:3, 3]
