"""BlenderProc's armature for a URDF robot (its ``URDFLoader.create_bone`` and ``Link`` bone set-up), built on
:mod:`hybridgen.bproc.armature`.

Per joint, three bones from the joint's frame (the product of the joint origins from the root link, m): the
deform bone ``<joint>`` with its head at the joint and its tail 0.2 m along the joint axis (so the bone's Y
axis is the axis), an FK bone ``<joint>.fk`` and an IK bone ``<joint>.ik`` shifted by ``fk_offset`` /
``ik_offset`` (m), each parented to the same kind of bone of the parent joint. A fixed joint's bones have every
location and rotation limited to 0 (and every IK axis locked); a revolute joint's have location 0, rotation
X and Z 0 and Y within the joint's limits (free when it has none), IK locks on X and Z and the Y limits as IK
limits, and the deform bone copies the FK bone's rotation (``copy_rotation.fk``, influence 1) or the IK bone's
(``copy_rotation.ik``, influence 0) in world space. Other joint types get no constraint (BlenderProc warns):
their deform bone only follows its parent.

:func:`add_ik_controller` adds BlenderProc's IK pair for a link: a controller bone at the link's IK bone moved
by ``relative_location`` (parented to the root of the link's deform chain) and a constraint bone ending there
(the IK bone's direction, parented to the IK bone's old parent, the IK bone re-parented to it) with an IK
constraint aiming at the controller, chain length ``chain_length`` (0: to the root), limited like the link's
joint when it is revolute. :func:`set_bone_rotation` is BlenderProc's ``Link._set_rotation_euler``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..io.urdf import Joint, Robot
from ..logs import log_line
from .armature import Armature
from .bone import Bone, CopyRotation, IKConstraint, LimitLocation, LimitRotation
from .bone_math import AXES, rotate_euler_axis
from .session import Animated

SCENE_FRAME = 1
"""Blender's current scene frame, which BlenderProc leaves at Blender's default: edit-mode round trips reset the
armature's keyed values to their values at this frame (:meth:`~hybridgen.bproc.armature.Armature.reset_to_frame`)."""
BONE_LENGTH = 0.2
"""Length of every bone BlenderProc makes (m)."""
ZERO = (0.0, 0.0)


@dataclass
class RigJoint:
    """A URDF joint's bones: ``deform`` (moves the link's objects), ``fk`` and ``ik``."""

    name: str
    type: str
    deform: Bone
    fk: Bone
    ik: Bone

    def bones(self) -> list[Bone]:
        return [self.deform, self.fk, self.ik]


def _limit_rotation(bone: Bone, limits: list[tuple[float, float] | None]) -> None:
    """Limit Rotation (local) with ``limits`` per axis, and the IK locks / limits BlenderProc derives from it."""
    constraint = LimitRotation(list(limits), [limit if limit is not None else ZERO for limit in limits])
    bone.constraints.append(constraint)
    ik_limits_from(bone, constraint)


def ik_limits_from(bone: Bone, constraint: LimitRotation) -> None:
    """``set_ik_limits_from_rotation_constraint``: an axis limited to 0..0 is locked, another limited one is an
    IK limit."""
    for axis, limit in enumerate(constraint.limits):
        if limit is None:
            continue
        if limit[0] == limit[1] == 0.0:
            bone.ik_lock[axis] = True
        else:
            bone.ik_limits[axis] = (float(limit[0]), float(limit[1]))


def _joint_limits(joint: Joint) -> tuple[float, float] | None:
    if joint.lower is None and joint.upper is None:
        return None
    return (float(joint.lower or 0.0), float(joint.upper or 0.0))


def _add_joint(armature: Armature, joint: Joint, frame: np.ndarray, parent: RigJoint | None,
               offsets: tuple[np.ndarray, np.ndarray]) -> RigJoint:
    axis = frame[:3, :3] @ np.asarray(joint.axis, dtype=np.float64)
    norm = np.linalg.norm(axis)
    if norm == 0.0:
        raise InputError(f"bproc.loader.load_urdf: joint '{joint.name}' has a zero-length axis")
    head = frame[:3, 3]
    tail = head + axis / norm * BONE_LENGTH
    made = []
    for suffix, shift, parent_bone in (("", np.zeros(3), parent.deform if parent else None),
                                       (".fk", offsets[0], parent.fk if parent else None),
                                       (".ik", offsets[1], parent.ik if parent else None)):
        made.append(armature.add(Bone(joint.name + suffix, head + shift, tail + shift, parent_bone)))
    rig = RigJoint(joint.name, joint.type, *made)
    if joint.type in ("fixed", "revolute"):
        rotation = [ZERO, ZERO, ZERO] if joint.type == "fixed" else [ZERO, _joint_limits(joint), ZERO]
        for bone in rig.bones():
            bone.constraints.append(LimitLocation([ZERO, ZERO, ZERO]))
            _limit_rotation(bone, rotation)
    else:
        log_line(f"bproc.loader.load_urdf: no constraint for joint type '{joint.type}' (joint '{joint.name}'), as "
                 "in BlenderProc: its link does not move with it", "warning")
    if joint.type == "revolute":
        rig.deform.constraints.append(CopyRotation("copy_rotation.fk", rig.fk, Animated(1.0)))
        rig.deform.constraints.append(CopyRotation("copy_rotation.ik", rig.ik, Animated(0.0)))
    return rig


def build_rig(robot: Robot, fk_offset: Any = None, ik_offset: Any = None) -> tuple[Armature, dict[str, RigJoint]]:
    """The armature of ``robot`` (module documentation) and its joints' bones by joint name."""
    offsets = (np.array([0.0, -1.0, 0.0] if fk_offset is None else fk_offset, dtype=np.float64).reshape(3),
               np.array([0.0, 1.0, 0.0] if ik_offset is None else ik_offset, dtype=np.float64).reshape(3))
    armature, rigs = Armature(), {}
    children = {joint.child for joint in robot.joints}
    base = next((link.name for link in robot.links if link.name not in children), robot.links[0].name)

    def grow(joint: Joint, frame: np.ndarray, parent: RigJoint | None) -> None:
        frame = frame @ joint.origin
        rigs[joint.name] = _add_joint(armature, joint, frame, parent, offsets)
        for child in (j for j in robot.joints if j.parent == joint.child):
            grow(child, frame, rigs[joint.name])

    for joint in (j for j in robot.joints if j.parent == base):
        grow(joint, np.eye(4), None)
    armature.update()
    return armature, rigs


def add_ik_controller(armature: Armature, rig: RigJoint, relative_location: Sequence[float], use_rotation: bool,
                      chain_length: int) -> tuple[Bone, Bone]:
    """BlenderProc's IK pair for ``rig``'s link (module documentation): (constraint bone, controller bone)."""
    shift = np.asarray(relative_location, dtype=np.float64).reshape(3)
    root = rig.deform
    while root.parent is not None:
        root = root.parent
    if rig.deform.parent is None or rig.ik.parent is None:
        raise InputError(f"bproc.types.URDFObject.create_ik_bone_controller: link of joint '{rig.name}' has no "
                         "parent joint to move (BlenderProc fails on it too)")
    controller = armature.add(Bone(rig.ik.name + ".controller", rig.ik.head + shift, rig.ik.tail + shift, root))
    tail = rig.ik.head + shift
    constraint = armature.add(Bone(rig.ik.name + ".constraint", tail - (rig.ik.tail - rig.ik.head), tail,
                                   rig.ik.parent))
    rig.ik.parent = constraint
    armature.reset_to_frame(SCENE_FRAME)
    constraint.ik = IKConstraint(controller, chain_count=int(chain_length), use_rotation=bool(use_rotation))
    limit = rig.deform.constraint(LimitRotation)
    if rig.type == "revolute" and limit is not None:
        ik_limits_from(constraint, limit)
    return constraint, controller


def rotation_axis(bone: Bone) -> str | None:
    """``Link._determine_rotation_axis``: the one axis the bone's Limit Rotation leaves free (None: no such
    constraint)."""
    limit = bone.constraint(LimitRotation)
    if limit is None:
        return None
    free = [axis for axis, value in zip(AXES, limit.limits) if not (value is not None and value[0] == value[1])]
    if len(free) != 1:
        raise InputError(f"bone '{bone.name}': its rotation limits leave {len(free)} axes free, not one")
    return free[0]


def clipped(bone: Bone, value: float, axis: str) -> float:
    """``Link._clip_value_from_constraint``: ``value`` clipped to the stored min/max of the bone's Limit
    Rotation on ``axis`` (0..0 where BlenderProc set none, as it reads them)."""
    limit = bone.constraint(LimitRotation)
    if limit is None:
        return value
    lo, hi = limit.stored[AXES.index(axis)]
    return min(max(value, lo), hi)


def set_bone_rotation(bone: Bone, rotation_euler: Any, mode: str, call: str) -> None:
    """``Link._set_rotation_euler``: absolute (clipped) or relative (turned about the bone's own axes) rotation,
    one angle about the bone's free axis or three XYZ angles."""
    if mode not in ("absolute", "relative"):
        raise InputError(f"{call}: mode must be 'absolute' or 'relative', got {mode!r}")
    single = np.ndim(rotation_euler) == 0
    current = np.array(bone.rotation.value, dtype=np.float64)
    if mode == "absolute":
        if single:
            axis = rotation_axis(bone)
            if axis is None:
                raise InputError(f"{call}: bone '{bone.name}' has no rotation limits to find its axis from; give "
                                 "three angles")
            current[AXES.index(axis)] = clipped(bone, float(rotation_euler), axis)
        else:
            current = np.array([clipped(bone, float(v), a) for v, a in zip(_three(rotation_euler, call), AXES)])
    elif single:
        axis = rotation_axis(bone)
        for turn_axis in (AXES if axis is None else (axis,)):
            current = rotate_euler_axis(current, turn_axis, float(rotation_euler))
    else:
        for turn_axis, angle in zip(AXES, _three(rotation_euler, call)):
            current = rotate_euler_axis(current, turn_axis, float(angle))
    bone.rotation.set(current)


def _three(values: Any, call: str) -> list[float]:
    flat = np.asarray(values, dtype=np.float64).reshape(-1)
    if flat.size != 3:
        raise InputError(f"{call}: rotation_euler must be one angle or three (XYZ), got {flat.size}")
    return [float(v) for v in flat]
