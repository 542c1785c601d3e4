"""A small stand-in for Blender's ``mathutils`` module, for what BlenderProc's example scripts use of it:
``Vector``, ``Matrix`` (``Matrix.Rotation``, ``@``, ``to_3x3``/``to_4x4``, ``inverted``, ``transposed``,
``translation``, ``to_euler``, ``to_quaternion``), ``Euler`` (Blender ``XYZ`` order only, radians; ``to_matrix``,
``rotate``) and ``Quaternion`` (``w, x, y, z``). Each converts to a NumPy array (``np.array(m)``) as the real types
do. ``mathutils.bvhtree.BVHTree`` is :class:`hybridgen.bproc.types.bvh_tree.BVHTree`. Anything else raises one line
naming the attribute.

``hybridgen run`` puts this module in ``sys.modules['mathutils']`` for the script (:mod:`hybridgen.bproc.script`).
Rotations follow Blender's conventions: right-handed, column vectors, ``Matrix.Rotation(angle, size, axis)``
turns counter-clockwise by ``angle`` rad about ``axis`` (``'X'``, ``'Y'``, ``'Z'`` or a 3-vector).
"""
from __future__ import annotations

import types
from typing import Any, Iterator, Sequence

import numpy as np

from ..scene.frames import euler_xyz_to_matrix, matrix_to_euler_xyz, rotation_about_axis
from .types.unsupported import fail

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


class _Array:
    """An array-valued mathutils object: indexing, iteration, ``np.array(x)`` and equality."""

    _values: np.ndarray

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self._values.astype(dtype or np.float64, copy=True)

    def __getitem__(self, index: Any) -> Any:
        item = self._values[index]
        return Vector(item) if isinstance(item, np.ndarray) and item.ndim == 1 else item

    def __setitem__(self, index: Any, value: Any) -> None:
        self._values[index] = np.asarray(value, dtype=np.float64)

    def __len__(self) -> int:
        return len(self._values)

    def __iter__(self) -> Iterator[Any]:
        return (self[i] for i in range(len(self)))

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and np.array_equal(self._values, np.asarray(other))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._values.tolist()})"

    def copy(self) -> Any:
        return type(self)(self._values.copy())


class Vector(_Array):
    """A vector of 2 to 4 floats (``x``, ``y``, ``z``, ``w``)."""

    def __init__(self, values: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        self._values = np.array(values, dtype=np.float64).reshape(-1)

    x = property(lambda self: float(self._values[0]))
    y = property(lambda self: float(self._values[1]))
    z = property(lambda self: float(self._values[2]))
    w = property(lambda self: float(self._values[3]))

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self._values))

    def normalized(self) -> "Vector":
        length = self.length
        return Vector(self._values / length if length > 0 else self._values)

    def dot(self, other: Any) -> float:
        return float(self._values @ np.asarray(other, dtype=np.float64))

    def cross(self, other: Any) -> "Vector":
        return Vector(np.cross(self._values, np.asarray(other, dtype=np.float64)))

    def to_3d(self) -> "Vector":
        return Vector(np.resize(np.append(self._values, [0.0, 0.0]), 3))

    def to_4d(self) -> "Vector":
        return Vector(np.append(self.to_3d()._values, 1.0))

    def __add__(self, other: Any) -> "Vector":
        return Vector(self._values + np.asarray(other, dtype=np.float64))

    def __sub__(self, other: Any) -> "Vector":
        return Vector(self._values - np.asarray(other, dtype=np.float64))

    def __mul__(self, scalar: float) -> "Vector":
        return Vector(self._values * float(scalar))

    __rmul__ = __mul__
    __radd__ = __add__

    def __rsub__(self, other: Any) -> "Vector":
        return Vector(np.asarray(other, dtype=np.float64) - self._values)

    def __truediv__(self, scalar: float) -> "Vector":
        return Vector(self._values / float(scalar))

    def __neg__(self) -> "Vector":
        return Vector(-self._values)

    def __matmul__(self, other: Any) -> Any:
        if isinstance(other, Matrix):
            return Vector(self._values @ other._values)
        return self.dot(other)


class Matrix(_Array):
    """A square matrix (rows), 2x2 to 4x4; ``m @ v`` for a Vector, ``m @ n`` for a Matrix."""

    def __init__(self, rows: Any = None) -> None:
        self._values = np.eye(4) if rows is None else np.array(rows, dtype=np.float64)
        if self._values.ndim != 2:
            raise ValueError(f"Matrix needs rows of numbers, got shape {self._values.shape}")

    @staticmethod
    def Identity(size: int) -> "Matrix":  # noqa: N802 - mathutils' name
        return Matrix(np.eye(size))

    @staticmethod
    def Rotation(angle: float, size: int, axis: Any) -> "Matrix":  # noqa: N802 - mathutils' name
        """A ``size`` x ``size`` rotation by ``angle`` rad about ``axis`` ('X', 'Y', 'Z' or a 3-vector)."""
        vector = np.asarray(AXES[axis.upper()] if isinstance(axis, str) else axis, dtype=np.float64)
        turn = np.asarray(angle, dtype=np.float64)
        if turn.size != 1:
            raise ValueError(f"Matrix.Rotation: angle must be one number, got {turn.tolist()}")
        rotation = rotation_about_axis(vector / np.linalg.norm(vector), float(turn.reshape(-1)[0]))  # a 1-array too
        return Matrix(rotation).to_4x4() if size == 4 else Matrix(rotation[:size, :size])

    @staticmethod
    def Translation(vector: Sequence[float]) -> "Matrix":  # noqa: N802 - mathutils' name
        matrix = np.eye(4)
        matrix[:3, 3] = np.asarray(vector, dtype=np.float64)[:3]
        return Matrix(matrix)

    @property
    def translation(self) -> Vector:
        return Vector(self._values[:3, 3])

    @translation.setter
    def translation(self, value: Sequence[float]) -> None:
        self._values[:3, 3] = np.asarray(value, dtype=np.float64)

    def to_3x3(self) -> "Matrix":
        return Matrix(self._values[:3, :3])

    def to_4x4(self) -> "Matrix":
        matrix = np.eye(4)
        size = min(len(self._values), 4)
        matrix[:size, :size] = self._values[:size, :size]
        return Matrix(matrix)

    def inverted(self) -> "Matrix":
        return Matrix(np.linalg.inv(self._values))

    def transposed(self) -> "Matrix":
        return Matrix(self._values.T)

    def to_euler(self, order: str = "XYZ") -> "Euler":
        """Blender's choice of the two XYZ triples (:func:`hybridgen.bproc.math.blender_euler_from_matrix`)."""
        from .math import blender_euler_from_matrix

        _xyz_only(order)
        return Euler(blender_euler_from_matrix(self._values[:3, :3]))

    def to_quaternion(self) -> "Quaternion":
        from scipy.spatial.transform import Rotation

        linear = self._values[:3, :3]
        x, y, z, w = Rotation.from_matrix(linear / np.linalg.norm(linear, axis=0)).as_quat()
        return Quaternion((w, x, y, z))

    def __matmul__(self, other: Any) -> Any:
        if isinstance(other, Matrix):
            return Matrix(self._values @ other._values)
        vector = np.asarray(other, dtype=np.float64)
        if len(vector) == 3 and len(self._values) == 4:  # Blender treats a 3-vector as a point
            return Vector((self._values @ np.append(vector, 1.0))[:3])
        return Vector(self._values @ vector)


class Euler(_Array):
    """Blender Euler angles (rad), order ``XYZ``: ``R = Rz @ Ry @ Rx``."""

    def __init__(self, angles: Sequence[float] = (0.0, 0.0, 0.0), order: str = "XYZ") -> None:
        _xyz_only(order)
        self._values = np.array(angles, dtype=np.float64).reshape(3)
        self.order = "XYZ"

    x = property(lambda self: float(self._values[0]))
    y = property(lambda self: float(self._values[1]))
    z = property(lambda self: float(self._values[2]))

    def to_matrix(self) -> Matrix:
        return Matrix(euler_xyz_to_matrix(self._values))

    def to_quaternion(self) -> "Quaternion":
        return self.to_matrix().to_quaternion()

    def rotate(self, other: Any) -> None:
        """Turn by ``other`` (an Euler, Matrix or Quaternion) applied after this rotation, in place."""
        matrix = other.to_matrix() if isinstance(other, (Euler, Quaternion)) else Matrix(np.asarray(other))
        self._values = matrix_to_euler_xyz(np.asarray(matrix)[:3, :3] @ euler_xyz_to_matrix(self._values))


class Quaternion(_Array):
    """A unit quaternion ``(w, x, y, z)``; ``Quaternion(axis, angle)`` for an axis-angle."""

    def __init__(self, values: Sequence[float] = (1.0, 0.0, 0.0, 0.0), angle: float | None = None) -> None:
        if angle is not None:
            axis = np.asarray(values, dtype=np.float64)
            axis = axis / np.linalg.norm(axis)
            values = (np.cos(angle / 2), *(np.sin(angle / 2) * axis))
        self._values = np.array(values, dtype=np.float64).reshape(4)

    w = property(lambda self: float(self._values[0]))
    x = property(lambda self: float(self._values[1]))
    y = property(lambda self: float(self._values[2]))
    z = property(lambda self: float(self._values[3]))

    def to_matrix(self) -> Matrix:
        from scipy.spatial.transform import Rotation

        w, x, y, z = self._values
        return Matrix(Rotation.from_quat([x, y, z, w]).as_matrix())

    def to_euler(self, order: str = "XYZ") -> Euler:
        return self.to_matrix().to_euler(order)


def _xyz_only(order: str) -> None:
    if order != "XYZ":
        fail(f"mathutils Euler order {order!r}", "hybridgen's mathutils stand-in has Blender's XYZ order only")


def _bvh_tree() -> Any:
    from .types.bvh_tree import BVHTree

    return BVHTree


class _BvhTreeModule(types.ModuleType):
    def __getattr__(self, name: str) -> Any:
        if name == "BVHTree":
            return _bvh_tree()
        if name.startswith("__"):
            raise AttributeError(name)
        fail(f"mathutils.bvhtree.{name}", "hybridgen's mathutils stand-in has bvhtree.BVHTree only")


bvhtree = _BvhTreeModule("mathutils.bvhtree")


def __getattr__(name: str) -> Any:  # noqa: N807 - the module's own
    if name.startswith("__"):
        raise AttributeError(name)
    fail(f"mathutils.{name}", "hybridgen's mathutils stand-in has Vector, Matrix, Euler, Quaternion and "
                              "bvhtree.BVHTree only")
