"""Blender's bone and Euler arithmetic, as bpy 4.2 computes it, for :mod:`hybridgen.bproc.armature`.

All angles in radians, rotations as 3x3 NumPy matrices acting on column vectors, Euler angles in Blender's
``XYZ`` order (``R = Rz @ Ry @ Rx``, :func:`hybridgen.scene.frames.euler_xyz_to_matrix`).

- :func:`bone_rest_rotation`: a bone's rest orientation from its head->tail direction and roll (the bone's Y axis
  is the direction; X and Z follow Blender's minimal rotation from +Y, then the roll about Y).
- :func:`euler_candidates` / :func:`matrix_to_euler`: the two XYZ Euler triples of a rotation and the one Blender
  keeps (the smaller sum of absolute angles); :func:`compatible_euler` the one nearest a previous triple (each
  angle moved by whole turns), as ``Euler.rotate_axis`` and a pose bone's matrix setter leave them.
- :func:`rotate_euler_axis`: ``mathutils.Euler.rotate_axis`` (the rotation right-multiplied by a turn about
  one of its own axes).
- :func:`clamp_angle`: the Limit Rotation constraint's cyclic clamp (Blender 4.2, not the legacy one): an angle
  outside ``[lo, hi]`` moves to the nearer end, counting around the circle.
- :func:`twist_angle` / :func:`axis_angle`: the angle about one local axis that Blender's IK solver reads from a
  bone's rotation (the twist about Y; the Euler angle about X or Z).

tests/bproc/test_urdf_blender_table.py holds the rest rotations (and the poses they lead to) against bpy 4.2's
(tools/urdf_table.py).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..scene.frames import euler_xyz_to_matrix

AXES = ("X", "Y", "Z")
FLOAT_EPSILON = float(np.finfo(np.float32).eps)


def bone_rest_rotation(direction: Sequence[float], roll: float = 0.0) -> np.ndarray:
    """3x3 rest rotation (armature space) of a bone pointing along ``direction`` (head to tail) with ``roll``."""
    vector = np.asarray(direction, dtype=np.float64)
    x, y, z = vector / np.linalg.norm(vector)
    theta, spread = 1.0 + y, x * x + z * z
    if theta > 1e-5 or ((x != 0.0 or z != 0.0) and theta > 1e-9):
        if theta <= 1e-5:  # close to -Y: 1 + y from the spread, to first order, as Blender does
            theta = spread * 0.5 + spread * spread * 0.125
        rotation = np.array([[1.0 - x * x / theta, x, -x * z / theta],
                             [-x, y, -z],
                             [-x * z / theta, z, 1.0 - z * z / theta]])
    else:  # along -Y: a half turn about Z
        rotation = np.diag([-1.0, -1.0, 1.0])
    if roll:
        rotation = rotation_about(np.array([x, y, z]), roll) @ rotation
    return rotation


def rotation_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """3x3 rotation of ``angle`` about the unit vector ``axis`` (Rodrigues' formula)."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array([[c + x * x * t, x * y * t - z * s, x * z * t + y * s],
                     [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
                     [z * x * t - y * s, z * y * t + x * s, c + z * z * t]])


def normalized(rotation: np.ndarray) -> np.ndarray:
    """The 3x3 with each column scaled to unit length (Blender's ``normalize_m3``)."""
    lengths = np.linalg.norm(rotation, axis=0)
    return rotation / np.where(lengths > 0.0, lengths, 1.0)[None, :]


def euler_candidates(rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two XYZ Euler triples of a rotation (equal near gimbal lock)."""
    r = normalized(np.asarray(rotation, dtype=np.float64)[:3, :3])
    cy = math.hypot(r[0, 0], r[1, 0])
    if cy > 16.0 * FLOAT_EPSILON:
        first = np.array([math.atan2(r[2, 1], r[2, 2]), math.atan2(-r[2, 0], cy), math.atan2(r[1, 0], r[0, 0])])
        second = np.array([math.atan2(-r[2, 1], -r[2, 2]), math.atan2(-r[2, 0], -cy),
                           math.atan2(-r[1, 0], -r[0, 0])])
        return first, second
    first = np.array([math.atan2(-r[1, 2], r[1, 1]), math.atan2(-r[2, 0], cy), 0.0])
    return first, first.copy()


def matrix_to_euler(rotation: np.ndarray) -> np.ndarray:
    """The XYZ Euler triple Blender reads from a rotation: of the two, the one with the smaller absolute sum."""
    first, second = euler_candidates(rotation)
    return second if np.abs(first).sum() > np.abs(second).sum() else first


def compatible_euler(euler: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """``euler`` with each angle moved by whole turns to lie within half a turn of ``previous``."""
    out = np.array(euler, dtype=np.float64)
    for i in range(3):
        delta = out[i] - previous[i]
        if delta > math.pi:
            out[i] -= math.floor(delta / (2.0 * math.pi) + 0.5) * 2.0 * math.pi
        elif delta < -math.pi:
            out[i] += math.floor(-delta / (2.0 * math.pi) + 0.5) * 2.0 * math.pi
    return out


def matrix_to_compatible_euler(rotation: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """Of the two Euler triples of ``rotation``, made compatible with ``previous``, the nearer one."""
    first, second = (compatible_euler(e, previous) for e in euler_candidates(rotation))
    if np.abs(first - previous).sum() > np.abs(second - previous).sum():
        return second
    return first


def rotate_euler_axis(euler: Sequence[float], axis: str, angle: float) -> np.ndarray:
    """``Euler.rotate_axis(axis, angle)``: the rotation times a turn of ``angle`` about its own ``axis``."""
    turn = np.zeros(3)
    turn[AXES.index(axis)] = angle
    previous = np.asarray(euler, dtype=np.float64)
    return matrix_to_compatible_euler(euler_xyz_to_matrix(previous) @ euler_xyz_to_matrix(turn), previous)


def wrap_angle(angle: float) -> float:
    """``angle`` wrapped into [-pi, pi)."""
    b = angle * (0.5 / math.pi) + 0.5
    return ((b - math.floor(b)) - 0.5) * 2.0 * math.pi


def clamp_angle(angle: float, lo: float, hi: float) -> float:
    """The Limit Rotation constraint's cyclic clamp of ``angle`` to the directed range ``lo..hi``."""
    if hi - lo >= 2.0 * math.pi:
        return angle
    if hi <= lo:
        return lo
    lo_wrapped, hi_wrapped = wrap_angle(lo - angle), wrap_angle(hi - angle)
    if lo_wrapped < hi_wrapped:
        return angle + min(max(0.0, lo_wrapped), hi_wrapped)
    if hi_wrapped >= 0.0 or lo_wrapped <= 0.0:
        return angle
    return angle + (hi_wrapped if abs(hi_wrapped) < abs(lo_wrapped) else lo_wrapped)


def twist_angle(rotation: np.ndarray) -> float:
    """The angle of a rotation's twist about its local Y axis."""
    return 2.0 * math.atan2(rotation[0, 2] - rotation[2, 0], np.trace(rotation) + 1.0)


def axis_angle(rotation: np.ndarray, axis: int) -> float:
    """The angle a single-axis IK joint about local ``axis`` (0 X, 1 Y, 2 Z) reads from a rotation."""
    if axis == 1:
        return twist_angle(rotation)
    t = math.hypot(rotation[0, 0], rotation[0, 1])
    if t > 16.0 * np.finfo(np.float64).eps:
        return -math.atan2(rotation[1, 2], rotation[2, 2]) if axis == 0 else -math.atan2(rotation[0, 1],
                                                                                             rotation[0, 0])
    return -math.atan2(-rotation[2, 1], rotation[1, 1]) if axis == 0 else 0.0


def axis_rotation(angle: float, axis: int) -> np.ndarray:
    """3x3 rotation of ``angle`` about local axis ``axis`` (0 X, 1 Y, 2 Z)."""
    unit = np.zeros(3)
    unit[axis] = 1.0
    return rotation_about(unit, angle)


def quaternion_angle(rotation: np.ndarray) -> float:
    """The angle (radians, 0..pi) of a rotation matrix, as ``to_quaternion().angle`` gives it."""
    cosine = (np.trace(normalized(rotation[:3, :3])) - 1.0) / 2.0
    return float(math.acos(min(1.0, max(-1.0, cosine))))


def slerp_matrix(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """3x3 rotation a fraction ``t`` of the way from ``a`` to ``b`` (along the shortest arc)."""
    relative = a.T @ b
    angle = quaternion_angle(relative)
    if angle < 1e-12:
        return a.copy()
    axis = np.array([relative[2, 1] - relative[1, 2], relative[0, 2] - relative[2, 0],
                     relative[1, 0] - relative[0, 1]])
    norm = np.linalg.norm(axis)
    if norm < 1e-12:  # a half turn: the axis from the symmetric part
        axis = np.sqrt(np.clip((np.diag(relative) + 1.0) / 2.0, 0.0, None))
        norm = np.linalg.norm(axis)
    return a @ rotation_about(axis / norm, angle * t)
