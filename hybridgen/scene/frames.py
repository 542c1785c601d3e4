"""Camera frame conventions and rotations (docs/conventions.md section 1).

World: right-handed, Z up, metres. Camera poses are ``cam2world`` 4x4 matrices in **OpenCV axes**
(x right, y down, z forward). Blender camera axes are x right, y up, looking along -z; the two differ
by a rotation of pi about the camera x axis: ``cam2world_cv = cam2world_blender @ diag(1, -1, -1, 1)``.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import InputError

BLENDER_TO_OPENCV = np.diag([1.0, -1.0, -1.0, 1.0])
"""Right-multiplying a Blender-axes cam2world by this gives the OpenCV-axes cam2world (it is its own inverse)."""

Y_UP_TO_Z_UP = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
"""Rotation of +90 degrees about X: a +Y-up file's up axis becomes +Z ((x, y, z) -> (x, -z, y))."""

_AXIS_VECTORS = {"X": np.array([1.0, 0, 0]), "Y": np.array([0, 1.0, 0]), "Z": np.array([0, 0, 1.0])}


def blender_to_opencv(cam2world: np.ndarray) -> np.ndarray:
    """Convert a 4x4 cam2world from Blender camera axes to OpenCV camera axes."""
    return np.asarray(cam2world, dtype=np.float64) @ BLENDER_TO_OPENCV


def opencv_to_blender(cam2world: np.ndarray) -> np.ndarray:
    """Convert a 4x4 cam2world from OpenCV camera axes to Blender camera axes."""
    return np.asarray(cam2world, dtype=np.float64) @ BLENDER_TO_OPENCV


def source_frame_matrix(axes: Sequence[str]) -> np.ndarray:
    """4x4 signed axis-permutation matrix ``S`` with row i = the signed unit vector that ``axes[i]`` names.

    A frame whose axis i is ``axes[i]`` of a reference frame maps points as ``p_ref = S^T p`` (S is
    orthonormal). For the two frames configs use the matrix is its own inverse:
    ``source_frame_matrix(["X", "-Y", "-Z"]) == BLENDER_TO_OPENCV``, so
    ``cam2world_opencv = cam2world_blender @ source_frame_matrix(["X", "-Y", "-Z"])``. What a config's
    ``source_frame`` means (BlenderProc's meaning) is applied by :mod:`hybridgen.config.camera_poses`,
    which reads a config's axes through this function.
    """
    if len(axes) != 3:
        raise ValueError(f"source_frame needs 3 axes like [X, -Y, -Z], got {list(axes)}")
    rows = []
    for axis in axes:
        text = str(axis).strip().upper()
        sign = -1.0 if text.startswith("-") else 1.0
        name = text.lstrip("+-")
        if name not in _AXIS_VECTORS:
            raise ValueError(f"source_frame axis must be one of X, Y, Z with an optional '-', got {axis!r}")
        rows.append(sign * _AXIS_VECTORS[name])
    # source axis i expressed in OpenCV camera coordinates = rows[i]; the matrix S maps cv -> source
    # coordinates, i.e. p_src = S p_cv with S[i] = rows[i] (rows are orthonormal).
    rot = np.array(rows) + 0.0  # no -0.0 entries: products with the matrix keep the bytes of plain zeros
    if abs(abs(np.linalg.det(rot)) - 1.0) > 1e-9:
        raise ValueError(f"source_frame axes {list(axes)} repeat an axis")
    out = np.eye(4)
    out[:3, :3] = rot
    return out


def _rotation() -> Any:
    """SciPy's ``Rotation``, imported on first use (``scipy.spatial`` costs ~0.17 s of start-up that a
    labels-only run with no Euler angles need not pay)."""
    from scipy.spatial.transform import Rotation

    return Rotation


def euler_xyz_to_matrix(angles: Sequence[float]) -> np.ndarray:
    """3x3 rotation from Blender ``XYZ`` Euler angles in radians: ``R = Rz(c) @ Ry(b) @ Rx(a)``.

    That is SciPy's extrinsic ``"xyz"`` (rotate about world X, then world Y, then world Z); every Euler
    angle in hybridgen goes through this one convention (docs/conventions.md section 1).
    """
    values = np.asarray(angles, dtype=np.float64).ravel()
    if values.size != 3:
        raise ValueError(f"Euler XYZ rotation needs 3 angles, got {list(values)}")
    if not values.any():  # no rotation (every loader's default): SciPy's exact identity
        return np.eye(3)
    quaternion = [0.0, 0.0, 0.0, 1.0]
    for axis, angle in enumerate(values.tolist()):  # extrinsic: each turn composed on the left
        turn = [0.0, 0.0, 0.0, math.cos(angle / 2.0)]
        turn[axis] = math.sin(angle / 2.0)
        quaternion = turn if axis == 0 else _compose_quaternions(turn, quaternion)
    return _quaternion_matrix(quaternion)


def _compose_quaternions(p: list[float], q: list[float]) -> list[float]:
    """The (x, y, z, w) quaternion ``p * q`` (``q``'s turn first), in SciPy's ``compose_quat`` operation
    order, so :func:`euler_xyz_to_matrix` gives SciPy's ``Rotation.from_euler("xyz", ...).as_matrix()`` bit for
    bit without importing SciPy (``scipy.spatial`` costs ~0.17 s of a process's start; held against SciPy in
    tests/scene/test_rotations_scipy.py)."""
    cross = (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])
    return [p[3] * q[0] + q[3] * p[0] + cross[0], p[3] * q[1] + q[3] * p[1] + cross[1],
            p[3] * q[2] + q[3] * p[2] + cross[2], p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2]]


def _quaternion_matrix(quaternion: list[float]) -> np.ndarray:
    """3x3 rotation of an (x, y, z, w) quaternion, in SciPy's ``as_matrix`` operation order (not normalised)."""
    x, y, z, w = quaternion
    x2, y2, z2, w2 = x * x, y * y, z * z, w * w
    xy, zw, xz, yw, yz, xw = x * y, z * w, x * z, y * w, y * z, x * w
    return np.array([[x2 - y2 - z2 + w2, 2 * (xy - zw), 2 * (xz + yw)],
                     [2 * (xy + zw), -x2 + y2 - z2 + w2, 2 * (yz - xw)],
                     [2 * (xz - yw), 2 * (yz + xw), -x2 - y2 + z2 + w2]])


def matrix_to_euler_xyz(rotation: np.ndarray) -> np.ndarray:
    """Blender ``XYZ`` Euler angles (radians) of a 3x3 rotation; the inverse of :func:`euler_xyz_to_matrix`.

    SciPy's ``Rotation.from_matrix(rotation).as_euler("xyz")`` bit for bit (its quaternion from the matrix, then
    Bernardes and Viollet's angles from the quaternion, in SciPy's operation order; held against SciPy in
    tests/scene/test_rotations_scipy.py) without importing SciPy, whose ``scipy.spatial`` costs ~0.17 s of every
    BlenderProc script's start (each new object's pose is decomposed). A matrix that is not orthogonal to SciPy's
    tolerance (which SciPy first projects onto the rotations), a gimbal lock (SciPy warns) and a non-positive
    determinant (SciPy's error) go to SciPy itself."""
    matrix = np.asarray(rotation, dtype=np.float64)
    if matrix.shape != (3, 3) or not _orthogonal(matrix):
        return _rotation().from_matrix(matrix).as_euler("xyz")
    m = matrix.tolist()
    trace = m[0][0] + m[1][1] + m[2][2]
    decision = [m[0][0], m[1][1], m[2][2], trace]
    choice = decision.index(max(decision))  # the first maximum, as argmax
    if choice == 3:
        quat = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1], 1 + trace]
    else:
        i, j, k = choice, (choice + 1) % 3, (choice + 2) % 3
        quat = [0.0] * 4
        quat[i] = 1 - trace + 2 * m[i][i]
        quat[j] = m[j][i] + m[i][j]
        quat[k] = m[k][i] + m[i][k]
        quat[3] = m[k][j] - m[j][k]
    norm = math.sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3])
    if not norm > 0:
        return _rotation().from_matrix(matrix).as_euler("xyz")
    x, y, z, w = (q / norm for q in quat)
    a, b, c, d = w - y, x + z, y + w, z - x  # extrinsic xyz: i, j, k = 0, 1, 2, sign +1
    # the C library's atan2 (math's) and hypot, as SciPy's compiled code calls them - not NumPy's vectorised ones,
    # nor math.hypot (Python's own, which differs from the C library's in the last bit now and then)
    hypot = _c_hypot()
    if hypot is None:
        return _rotation().from_matrix(matrix).as_euler("xyz")
    half_sum, half_diff = math.atan2(b, a), math.atan2(d, c)
    second = 2 * math.atan2(hypot(c, d), hypot(a, b))
    if abs(second) <= 1e-7 or abs(second - math.pi) <= 1e-7:  # gimbal lock
        return _rotation().from_matrix(matrix).as_euler("xyz")
    angles = [half_sum - half_diff, second - math.pi / 2, half_sum + half_diff]
    for index, angle in enumerate(angles):  # into [-pi, pi], as SciPy's compiled backend does
        if angle < -math.pi:
            angles[index] = angle + 2 * math.pi
        elif angle > math.pi:
            angles[index] = angle - 2 * math.pi
    return np.array(angles, dtype=np.float64)


@lru_cache(maxsize=1)
def _c_hypot() -> Callable[[float, float], float] | None:
    """The C math library's ``hypot``, or None where it cannot be loaded."""
    import ctypes
    import ctypes.util

    try:
        library = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
        function = library.hypot
    except (OSError, AttributeError):
        return None
    function.restype, function.argtypes = ctypes.c_double, [ctypes.c_double, ctypes.c_double]
    return function


def _orthogonal(matrix: np.ndarray) -> bool:
    """SciPy's test before ``from_matrix``: positive determinant, ``M M^T`` within (rtol 1e-5, atol 1e-12) of I."""
    if not np.linalg.det(matrix) > 0:
        return False
    return bool(np.all(np.abs(matrix @ matrix.T - np.eye(3)) <= 1e-12 + 1e-5 * np.ones((3, 3))))


def rotation_about_axis(axis: np.ndarray, angle: float) -> np.ndarray:
    """3x3 rotation of ``angle`` radians about ``axis`` (right-hand rule; any non-zero length)."""
    axis = np.asarray(axis, dtype=np.float64)
    return _rotation().from_rotvec(axis / np.linalg.norm(axis) * float(angle)).as_matrix()


def forward_to_rotation_blender(forward: Sequence[float], inplane_rot: float = 0.0) -> np.ndarray:
    """Blender-axes camera rotation (3x3, camera->world) whose view direction (-z) is ``forward``.

    The image "up" (+y in Blender axes) is as close as possible to world +Z; ``inplane_rot`` (radians)
    then rotates the camera about its own Blender z axis (right-multiplied, as BlenderProc does).
    Looking straight up or down, image up is world +Y.
    """
    fwd = np.asarray(forward, dtype=np.float64)
    norm = np.linalg.norm(fwd)
    if not np.isfinite(norm) or norm == 0:
        raise ValueError(f"forward vector must be finite and non-zero, got {list(fwd)}")
    fwd = fwd / norm
    up_world = np.array([0.0, 0.0, 1.0])
    right = np.cross(fwd, up_world)
    if np.linalg.norm(right) < 1e-9:  # looking along +-Z: pick world +Y as up
        right = np.cross(fwd, np.array([0.0, 1.0, 0.0]))
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rot = np.stack([right, up, -fwd], axis=1)
    if inplane_rot:
        rot = rot @ rotation_about_axis(np.array([0.0, 0.0, 1.0]), float(inplane_rot))
    return rot


def look_at_blender(location: Sequence[float], target: Sequence[float], inplane_rot: float = 0.0) -> np.ndarray:
    """Blender-axes 3x3 camera rotation looking from ``location`` to ``target`` (docs/conventions.md section 1)."""
    return forward_to_rotation_blender(np.asarray(target, float) - np.asarray(location, float), inplane_rot)


def make_pose(rotation: np.ndarray, location: Sequence[float]) -> np.ndarray:
    """4x4 homogeneous transform from a 3x3 rotation and a translation (metres)."""
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:3, 3] = np.asarray(location, dtype=np.float64)
    return pose


def object_pose(location: Sequence[float] = (0, 0, 0), rotation: Sequence[float] = (0, 0, 0),
                scale: float | Sequence[float] = 1.0) -> np.ndarray:
    """4x4 local2world from a location (m), Blender XYZ Euler rotation (rad) and scale (uniform or per axis)."""
    factors = np.broadcast_to(np.asarray(scale, dtype=np.float64), (3,))
    if np.any(factors == 0) or not np.all(np.isfinite(factors)):
        raise InputError(f"scale must be finite and non-zero, got {list(factors)}")
    return make_pose(euler_xyz_to_matrix(rotation) @ np.diag(factors), location)
