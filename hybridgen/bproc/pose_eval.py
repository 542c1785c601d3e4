"""One evaluation of an armature's pose (:mod:`hybridgen.bproc.armature`): bones posed on demand, parents,
constraint targets and IK chains first; an IK chain is posed without IK, then solved
(:func:`hybridgen.bproc.bone_ik.solve`) and its bones turned by the solution. Matrices 4x4, armature space, m.
"""
from __future__ import annotations

import numpy as np

from ..scene.frames import euler_xyz_to_matrix
from .bone import Bone, CopyRotation, LimitLocation, LimitRotation
from .bone_ik import Segment, solve
from .bone_math import clamp_angle, matrix_to_euler, normalized, slerp_matrix


def _local_limits(matrix: np.ndarray, frame_of: np.ndarray, constraint: LimitLocation | LimitRotation) -> np.ndarray:
    """``matrix`` (pose) with a local-space limit applied; ``frame_of`` = parent pose @ rest offset."""
    local = np.linalg.inv(frame_of) @ matrix
    if isinstance(constraint, LimitLocation):
        for axis, limit in enumerate(constraint.limits):
            if limit is not None:
                local[axis, 3] = min(max(local[axis, 3], limit[0]), limit[1])
    else:
        scale = np.linalg.norm(local[:3, :3], axis=0)
        euler = matrix_to_euler(local[:3, :3])
        for axis, limit in enumerate(constraint.limits):
            if limit is not None:
                euler[axis] = clamp_angle(float(euler[axis]), *limit)
        local[:3, :3] = euler_xyz_to_matrix(euler) * scale[None, :]
    return frame_of @ local


def _copy_rotation(matrix: np.ndarray, target: np.ndarray, influence: float) -> np.ndarray:
    if influence <= 0.0:
        return matrix
    out = matrix.copy()
    scale = np.linalg.norm(matrix[:3, :3], axis=0)
    own = normalized(matrix[:3, :3])
    rotation = normalized(target[:3, :3]) if influence >= 1.0 else slerp_matrix(own, normalized(target[:3, :3]),
                                                                                influence)
    out[:3, :3] = rotation * scale[None, :]
    return out


class Evaluation:
    """One evaluation pass: bones posed on demand (parents, constraint targets and IK chains first)."""

    def __init__(self, bones: dict[str, Bone], frame: int | None) -> None:
        self.bones, self.frame = bones, frame
        self.done: dict[str, np.ndarray] = {}
        self.chains = {}
        for bone in bones.values():
            if bone.ik is not None and bone.ik.influence.at(frame) > 0.0:
                for member in bone.chain():
                    self.chains.setdefault(member.name, bone)

    def run(self) -> dict[str, np.ndarray]:
        for bone in self.bones.values():
            self.pose(bone)
        return self.done

    def pose(self, bone: Bone) -> np.ndarray:
        if bone.name not in self.done:
            tip = self.chains.get(bone.name)
            if tip is not None:
                self._solve(tip)
            else:
                parent = None if bone.parent is None else self.pose(bone.parent)
                self.done[bone.name] = self._plain(bone, parent)
        return self.done[bone.name]

    def _plain(self, bone: Bone, parent: np.ndarray | None) -> np.ndarray:
        """The bone posed from its parent's pose and its own basis and constraints (no IK)."""
        frame_of = (np.eye(4) if parent is None else parent) @ bone.rest_offset()
        matrix = frame_of @ bone.basis(self.frame)
        for constraint in bone.constraints:
            if isinstance(constraint, CopyRotation):
                matrix = _copy_rotation(matrix, self.pose(constraint.target), constraint.influence.at(self.frame))
            else:
                matrix = _local_limits(matrix, frame_of, constraint)
        return matrix

    def _solve(self, tip: Bone) -> None:
        assert tip.ik is not None
        chain = tip.chain()
        names = {bone.name for bone in chain}
        for bone in chain:
            self.chains.pop(bone.name, None)
        for bone in chain:  # posed without IK first (targets reading them during the solve see these)
            parent = None if bone.parent is None else (self.done[bone.parent.name] if bone.parent.name in names
                                                       else self.pose(bone.parent))
            self.done[bone.name] = self._plain(bone, parent)
        before = {bone.name: self.done[bone.name] for bone in chain}
        root = chain[0]
        root_frame = np.eye(4) if root.parent is None else self.pose(root.parent).copy()
        root_frame[:3, :3] = normalized(root_frame[:3, :3])
        root_frame[:3, 3] = before[root.name][:3, 3]
        goal = np.linalg.inv(root_frame) @ self.pose(tip.ik.target)
        changes, _ = solve(_segments(chain, before, self.done), *self._goal(tip, before, root_frame, goal),
                           weight=tip.ik.weight, orient_weight=tip.ik.orient_weight, iterations=tip.ik.iterations)
        for bone, change in zip(chain, changes):
            parent_before = np.eye(4) if bone.parent is None else (before[bone.parent.name]
                                                                  if bone.parent.name in names
                                                                  else self.done[bone.parent.name])
            local = np.linalg.inv(parent_before) @ before[bone.name]
            turn = np.eye(4)
            turn[:3, :3] = change
            parent_after = np.eye(4) if bone.parent is None else self.done[bone.parent.name]
            self.done[bone.name] = parent_after @ local @ turn

    def _goal(self, tip: Bone, before: dict[str, np.ndarray], root_frame: np.ndarray,
              goal: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """Goal position and rotation in the chain's root frame, blended toward the tip by a partial influence."""
        assert tip.ik is not None
        position, rotation = goal[:3, 3].copy(), normalized(goal[:3, :3])
        influence = float(tip.ik.influence.at(self.frame))
        if influence < 1.0:
            end = np.linalg.inv(root_frame) @ before[tip.name]
            end_tail = end[:3, :3] @ np.array([0.0, tip.length, 0.0]) + end[:3, 3]
            position = influence * position + (1.0 - influence) * end_tail
            rotation = slerp_matrix(normalized(end[:3, :3]), rotation, influence)
        return position, rotation if tip.ik.use_rotation else None


def _segments(chain: list[Bone], before: dict[str, np.ndarray], done: dict[str, np.ndarray]) -> list[Segment]:
    """The IK segments of a chain posed as ``before`` (module documentation of :mod:`bone_ik`)."""
    segments = []
    for index, bone in enumerate(chain):
        pose = before[bone.name]
        parent_pose = None if bone.parent is None else before.get(bone.parent.name, done.get(bone.parent.name))
        parent_rotation = np.eye(3) if parent_pose is None else normalized(parent_pose[:3, :3])
        start = np.zeros(3)
        if parent_pose is not None and index > 0:
            parent_tail = parent_pose[:3, 3] + parent_pose[:3, 1] * bone.parent.length
            start = parent_rotation.T @ (pose[:3, 3] - parent_tail)
        rest = bone.rest_offset()[:3, :3]
        basis = rest.T @ parent_rotation.T @ normalized(pose[:3, :3])
        free = [axis for axis in range(3) if not bone.ik_lock[axis]]
        if len(free) == 2:
            raise ValueError(f"bone '{bone.name}': an IK joint with two free axes is not supported")
        axis = free[0] if len(free) == 1 else None
        segments.append(Segment(start, rest, basis, bone.length * float(np.linalg.norm(pose[:3, 1])), axis=axis,
                                free=len(free) == 3, limits=None if axis is None else bone.ik_limits[axis]))
    return segments
