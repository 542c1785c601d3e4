"""A Blender armature's pose, evaluated as bpy 4.2 evaluates it: bones, their keyframable pose, their constraints
and IK chains. :mod:`hybridgen.bproc.urdf_rig` builds BlenderProc's URDF rig from it.

Frames and units: every matrix is 4x4 in armature space (metres; the armature object's own pose is applied by
its owner). A :class:`Bone` has a rest pose from its ``head`` and ``tail`` (armature space, m) and ``roll``
(:func:`~hybridgen.bproc.bone_math.bone_rest_rotation`: the bone's Y axis points head to tail) and a pose basis
``location`` (m, in its rest frame) and ``rotation`` (XYZ Euler, rad, about its rest axes), each an
:class:`~hybridgen.bproc.session.Animated` property (keyed per frame). A bone's pose matrix is its parent's pose
times the rest offset from the parent (``parent_rest^-1 @ rest``) times the basis, then its constraints
(:mod:`hybridgen.bproc.bone`) in order:

- ``LimitLocation`` / ``LimitRotation`` (local space: on the basis-like transform relative to the parent's pose
  and the rest offset; rotation limits clamp the Euler angles cyclically, Blender 4.2);
- ``CopyRotation`` (world space, replace): the bone takes its target's rotation, keeping its own head,
  blended by ``influence`` (an Animated property);
- ``IKConstraint`` on the tip of a chain of ``chain_count`` bones (0: up to the root): the chain's bones
  are first posed as above, then turned together (:func:`hybridgen.bproc.bone_ik.solve`) so that the tip's tail
  reaches the target bone's head (and, with ``use_rotation``, its frame the target's), each bone within its IK
  locks and limits (``ik_lock``, ``ik_limits``: per axis X, Y, Z); children follow the solved chain.

:meth:`Armature.evaluate` poses every bone from the values at a frame (their keys, :func:`~hybridgen.bproc.session.
hold_value`) or the current values; :meth:`Armature.update` stores the current pose as ``evaluated``, which is
what reads and :meth:`Armature.set_pose_matrix` (Blender's ``pose_bone.matrix = M``) use until the next update, as
Blender reads a pose bone's matrix from the last depsgraph evaluation.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .bone import Bone, CopyRotation
from .bone_math import matrix_to_euler
from .pose_eval import Evaluation

__all__ = ["Armature", "Bone"]


class Armature:
    """Bones by name in creation order, and the last evaluated pose (module documentation)."""

    CACHE_SIZE = 256
    """Evaluations kept, by the values they were made from."""

    def __init__(self) -> None:
        self.bones: dict[str, Bone] = {}
        self.evaluated: dict[str, np.ndarray] = {}
        self._cache: dict[bytes, dict[str, np.ndarray]] = {}

    def add(self, bone: Bone) -> Bone:
        self.bones[bone.name] = bone
        return bone

    def reset_to_frame(self, frame: int) -> None:
        """Set every keyed value's current value to its value at ``frame``: what Blender does to an armature's
        animated properties when its data is rebuilt (leaving edit mode re-evaluates the animation at the scene's
        frame and writes it back)."""
        for bone in self.bones.values():
            values = [bone.location, bone.rotation] + [getattr(c, "influence") for c in bone.constraints
                                                       if isinstance(c, CopyRotation)]
            for value in values + ([bone.ik.influence] if bone.ik is not None else []):
                if value.keys:
                    value.set(value.at(frame))

    def update(self) -> None:
        """Evaluate the current values into ``evaluated`` (Blender's ``view_layer.update()``)."""
        self.evaluated = self.evaluate(None)

    def pose(self, name: str) -> np.ndarray:
        """A bone's pose matrix as last evaluated."""
        return self.evaluated[name]

    def set_pose_matrix(self, bone: Bone, matrix: np.ndarray) -> None:
        """Blender's ``pose_bone.matrix = matrix``: the current basis that puts the bone there, from its parent's
        last evaluated pose (its own constraints ignored)."""
        parent = np.eye(4) if bone.parent is None else self.evaluated[bone.parent.name]
        local = np.linalg.inv(parent @ bone.rest_offset()) @ np.asarray(matrix, dtype=np.float64)
        bone.location.set(local[:3, 3].copy())
        bone.rotation.set(matrix_to_euler(local[:3, :3]))

    def evaluate(self, frame: int | None) -> dict[str, np.ndarray]:
        """Every bone's pose matrix from the values at ``frame`` (None: the current values); the dictionary is
        shared with later calls on the same values: read it, do not change it."""
        key = self._signature(frame)
        poses = self._cache.get(key)
        if poses is None:
            if len(self._cache) >= self.CACHE_SIZE:
                self._cache.clear()
            poses = self._cache[key] = Evaluation(self.bones, frame).run()
        return poses

    def _signature(self, frame: int | None) -> bytes:
        """Everything an evaluation at ``frame`` depends on, as bytes."""
        parts: list[Any] = []
        for bone in self.bones.values():
            parts += [bone.name, bone.parent.name if bone.parent else "", bone.head, bone.tail, bone.roll,
                      bone.location.at(frame), bone.rotation.at(frame), bone.ik_lock, bone.ik_limits]
            for constraint in bone.constraints:
                parts.append(constraint.influence.at(frame) if isinstance(constraint, CopyRotation)
                             else constraint.limits)
            if bone.ik is not None:
                parts += [bone.ik.target.name, bone.ik.chain_count, bone.ik.use_rotation, bone.ik.influence.at(frame),
                          bone.ik.weight, bone.ik.orient_weight, bone.ik.iterations]
        return repr([p.tolist() if isinstance(p, np.ndarray) else p for p in parts]).encode()
