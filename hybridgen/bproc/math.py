"""``bproc.math`` of BlenderProc 2.8: homogeneous transforms and changes of axis conventions, in NumPy.

Frames and units follow docs/conventions.md section 1: metres, radians, right-handed frames, Blender
``XYZ`` Euler angles (``R = Rz(c) @ Ry(b) @ Rx(a)``, SciPy's extrinsic ``"xyz"``). Matrices are NumPy
arrays that map column vectors (``p_dst = M @ [p_src, 1]``), as Blender's ``mathutils.Matrix`` does.

Blender's ``mathutils`` stores numbers in single precision; these functions compute in double precision,
so a result can differ from BlenderProc's in the 8th significant digit and no more.

Axis lists (``new_frame``) name each axis of the new frame by the old frame's axis it equals:
``["X", "-Z", "Y"]`` says new x = old x, new y = -old z, new z = old y, so the point (1, 2, 3) becomes
(1, -3, 2). Besides BlenderProc's four functions this module holds the Euler-angle conversions of
``mathutils`` (:func:`blender_euler_from_matrix`, :func:`matrix_from_blender_quaternion`) that the
``bproc`` layer needs to return the same angle triples as Blender.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ..scene.frames import euler_xyz_to_matrix

__all__ = ["build_transformation_mat", "change_coordinate_frame_of_point",
           "change_source_coordinate_frame_of_transformation_matrix",
           "change_target_coordinate_frame_of_transformation_matrix"]

_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}
_FLT_EPSILON = float(np.finfo(np.float32).eps)


def _axis(name: Any) -> tuple[int, float]:
    """(index, sign) of an axis name such as ``"X"`` or ``"-z"`` (BlenderProc reads the last letter and a
    leading ``-``)."""
    text = str(name).upper()
    if not text or text[-1] not in _AXIS_INDEX:
        raise ValueError(f"invalid axis {name!r}: use X, Y or Z with an optional '-'")
    return _AXIS_INDEX[text[-1]], -1.0 if text.startswith("-") else 1.0


def _frame_change(new_frame: Sequence[str]) -> np.ndarray:
    """4x4 signed permutation ``T`` with ``p_new = T @ p_old`` (row i selects the old axis ``new_frame[i]``)."""
    if len(new_frame) != 3:
        raise ValueError(f"a coordinate frame needs exactly three axes, got {list(new_frame)}")
    change = np.zeros((4, 4))
    for row, name in enumerate(new_frame):
        column, sign = _axis(name)
        change[row, column] = sign
    change[3, 3] = 1.0
    return change


def change_coordinate_frame_of_point(point: Any, new_frame: Sequence[str]) -> np.ndarray:
    """The 3-vector ``point`` expressed in ``new_frame`` (see the module docstring): component i of the
    result is the old component named by ``new_frame[i]``, negated for a ``-`` axis.

    Example: ``change_coordinate_frame_of_point([1, 2, 3], ["X", "-Z", "Y"])`` is ``[1, -3, 2]``.
    """
    if len(new_frame) != 3:
        raise ValueError(f"a coordinate frame needs exactly three axes, got {list(new_frame)}")
    values = np.array(point)
    picked = []
    for name in new_frame:
        index, sign = _axis(name)
        picked.append(values[index] * -1 if sign < 0 else values[index])
    return np.array(picked)


def change_target_coordinate_frame_of_transformation_matrix(matrix: Any, new_frame: Sequence[str]) -> np.ndarray:
    """Given a 4x4 ``T_A^B`` mapping frame A to frame B, the ``T_A^B'`` mapping A to B', where B' has the axes
    ``new_frame`` of B: ``change @ matrix`` with ``change`` the signed axis permutation."""
    return _frame_change(new_frame) @ np.asarray(matrix, dtype=np.float64)


def change_source_coordinate_frame_of_transformation_matrix(matrix: Any, new_frame: Sequence[str]) -> np.ndarray:
    """Given a 4x4 ``T_A^B`` mapping frame A to frame B, the ``T_A'^B`` mapping A' to B, where A' has the
    axes ``new_frame`` of A: ``matrix @ inverse(change)``.

    The usual use: an OpenCV-axes cam2world (x right, y down, z forward) with ``["X", "-Y", "-Z"]`` becomes
    the Blender-axes cam2world (x right, y up, looking along -z) that ``bproc.camera.add_camera_pose`` takes.
    """
    change = _frame_change(new_frame)
    return np.asarray(matrix, dtype=np.float64) @ change.T  # a signed permutation's inverse is its transpose


def build_transformation_mat(translation: Any, rotation: Any) -> np.ndarray:
    """4x4 transform from a translation (3 values, metres) and a rotation: a 3x3 matrix, or three Blender
    ``XYZ`` Euler angles in radians (shape (3,) or (3, 1)).

    ``p_world = M @ [p_local, 1]``; for a camera pose pass a Blender-axes camera rotation (as
    ``bproc.camera.rotation_from_forward_vec`` returns) to get the cam2world ``add_camera_pose`` takes.
    """
    offset = np.array(translation, dtype=np.float64)
    turn = np.array(rotation, dtype=np.float64)
    if offset.ndim == 0 or offset.shape[0] != 3 or offset.size != 3:
        raise ValueError(f"translation has shape {offset.shape}: it must be a (3,) or (3, 1) vector")
    matrix = np.eye(4)
    matrix[:3, 3] = offset.ravel()
    if turn.shape == (3, 3):
        matrix[:3, :3] = turn
    elif turn.ndim >= 1 and turn.shape[0] == 3 and turn.size == 3:
        matrix[:3, :3] = euler_xyz_to_matrix(turn.ravel())
    else:
        raise ValueError(f"rotation has shape {turn.shape}: it must be a 3x3 matrix or three Euler angles")
    return matrix


def matrix_from_blender_quaternion(quaternion: Sequence[float]) -> np.ndarray:
    """3x3 rotation of a quaternion in Blender's component order ``(w, x, y, z)``, normalised first as
    ``mathutils.Quaternion.to_matrix`` / ``to_euler`` do."""
    w, x, y, z = np.asarray(quaternion, dtype=np.float64) / np.linalg.norm(quaternion)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def blender_euler_from_matrix(rotation: Any) -> np.ndarray:
    """Blender ``XYZ`` Euler angles (radians) of a 3x3 rotation, chosen as ``mathutils``' ``to_euler()``
    chooses them.

    Every rotation has two angle triples ``(a, b, c)`` with ``R = Rz(c) Ry(b) Rx(a)``: one with
    ``|b| <= pi/2`` (SciPy's ``as_euler("xyz")``) and ``(a +- pi, pi - b, c +- pi)``. Blender returns the one
    whose absolute values sum less, the first on a tie; near gimbal lock (``cos b`` under 16 float32
    epsilons) it sets ``c = 0``. Columns are normalised first, as Blender does.
    """
    matrix = np.asarray(rotation, dtype=np.float64)[:3, :3]
    matrix = matrix / np.linalg.norm(matrix, axis=0)
    cos_b = math.hypot(matrix[0, 0], matrix[1, 0])
    if cos_b <= 16.0 * _FLT_EPSILON:
        return np.array([math.atan2(-matrix[1, 2], matrix[1, 1]), math.atan2(-matrix[2, 0], cos_b), 0.0])
    first = np.array([math.atan2(matrix[2, 1], matrix[2, 2]), math.atan2(-matrix[2, 0], cos_b),
                      math.atan2(matrix[1, 0], matrix[0, 0])])
    second = np.array([math.atan2(-matrix[2, 1], -matrix[2, 2]), math.atan2(-matrix[2, 0], -cos_b),
                       math.atan2(-matrix[1, 0], -matrix[0, 0])])
    return second if np.abs(first).sum() > np.abs(second).sum() else first
