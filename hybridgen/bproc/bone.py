"""A Blender armature's bone and its constraints (:mod:`hybridgen.bproc.armature` documents how they pose it).

A :class:`Bone`'s rest pose comes from ``head`` and ``tail`` (armature space, m) and ``roll`` (rad); its pose
basis is ``location`` (m, rest frame) and ``rotation`` (XYZ Euler, rad), :class:`~hybridgen.bproc.session.Animated`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..scene.frames import euler_xyz_to_matrix
from .bone_math import bone_rest_rotation
from .session import Animated

Limits = list[tuple[float, float] | None]
"""Per axis X, Y, Z: (min, max) or None (free)."""


@dataclass
class LimitLocation:
    limits: Limits


@dataclass
class LimitRotation:
    """``limits`` per used axis; ``stored`` the min/max Blender keeps for every axis (0 where not set)."""

    limits: Limits
    stored: list[tuple[float, float]] = field(default_factory=lambda: [(0.0, 0.0)] * 3)


@dataclass
class CopyRotation:
    name: str
    target: "Bone"
    influence: Animated


@dataclass
class IKConstraint:
    target: "Bone"
    chain_count: int = 0
    use_rotation: bool = True
    influence: Animated = field(default_factory=lambda: Animated(1.0))
    weight: float = 1.0
    orient_weight: float = 1.0
    iterations: int = 500


class Bone:
    """One bone (module documentation)."""

    def __init__(self, name: str, head: Any, tail: Any, parent: "Bone | None" = None, roll: float = 0.0) -> None:
        self.name, self.parent, self.roll = name, parent, float(roll)
        self.head, self.tail = np.array(head, dtype=np.float64), np.array(tail, dtype=np.float64)
        self.location, self.rotation = Animated(np.zeros(3)), Animated(np.zeros(3))
        self.constraints: list[LimitLocation | LimitRotation | CopyRotation] = []
        self.ik: IKConstraint | None = None
        self.ik_lock = [False, False, False]
        self.ik_limits: Limits = [None, None, None]

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.tail - self.head))

    def rest(self) -> np.ndarray:
        """The rest matrix (armature space)."""
        matrix = np.eye(4)
        matrix[:3, :3] = bone_rest_rotation(self.tail - self.head, self.roll)
        matrix[:3, 3] = self.head
        return matrix

    def rest_offset(self) -> np.ndarray:
        """The rest pose relative to the parent's rest pose."""
        return self.rest() if self.parent is None else np.linalg.inv(self.parent.rest()) @ self.rest()

    def basis(self, frame: int | None) -> np.ndarray:
        matrix = np.eye(4)
        matrix[:3, :3] = euler_xyz_to_matrix(self.rotation.at(frame))
        matrix[:3, 3] = self.location.at(frame)
        return matrix

    def constraint(self, kind: type) -> Any:
        return next((c for c in self.constraints if isinstance(c, kind)), None)

    def copy_rotation(self, name: str) -> CopyRotation | None:
        return next((c for c in self.constraints if isinstance(c, CopyRotation) and c.name == name), None)

    def chain(self) -> list["Bone"]:
        """The bones its IK constraint moves, root first."""
        bones: list[Bone] = []
        bone: Bone | None = self
        while bone is not None and (self.ik is None or self.ik.chain_count == 0 or len(bones) < self.ik.chain_count):
            bones.insert(0, bone)
            bone = bone.parent
        return bones
