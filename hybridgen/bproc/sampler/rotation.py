"""``bproc.sampler.uniformSO3``: random rotations as Blender ``XYZ`` Euler angles (radians)."""
from __future__ import annotations

import random

import numpy as np

from ..math import blender_euler_from_matrix, matrix_from_blender_quaternion
from ...scene.frames import rotation_about_axis

__all__ = ["uniformSO3"]


def _uniform_quaternion() -> np.ndarray:
    """A unit quaternion ``(w, x, y, z)`` uniform over the rotations, from three ``np.random.rand`` draws
    (Shoemake's subgroup algorithm, in the component order BlenderProc uses)."""
    u = np.random.rand(3)
    low, high = np.sqrt(1.0 - u[0]), np.sqrt(u[0])
    first, second = 2.0 * np.pi * u[1], 2.0 * np.pi * u[2]
    return np.array([np.cos(second) * high, np.sin(first) * low, np.cos(first) * low, np.sin(second) * high])


def uniformSO3(around_x: bool = True, around_y: bool = True, around_z: bool = True) -> np.ndarray:
    """Blender ``XYZ`` Euler angles (radians, world axes) of a random rotation.

    With all three axes enabled the rotation is uniform over SO(3) (three ``np.random.rand`` draws). Else
    each enabled axis, in the order X, Y, Z, gets an angle from Python's ``random.uniform(0, 2 pi)`` and the
    rotation is ``Rx(a) @ Ry(b) @ Rz(c)`` of the enabled ones, as in BlenderProc. Either way the angles are
    the triple Blender's ``to_euler()`` would give (:func:`hybridgen.bproc.math.blender_euler_from_matrix`).
    """
    if around_x and around_y and around_z:
        return blender_euler_from_matrix(matrix_from_blender_quaternion(_uniform_quaternion()))
    rotation = np.eye(3)
    for enabled, axis in ((around_x, (1.0, 0.0, 0.0)), (around_y, (0.0, 1.0, 0.0)), (around_z, (0.0, 0.0, 1.0))):
        if enabled:
            rotation = rotation @ rotation_about_axis(np.array(axis), random.uniform(0, 2 * np.pi))
    return blender_euler_from_matrix(rotation)
