"""How a URDF robot's objects follow its bones (:mod:`hybridgen.bproc.urdf_object`): each visual, collision and
inertial object of a jointed link gets, as its pose in the robot's frame, its deform bone's motion from rest
(``pose @ rest^-1``, armature space) times its own undeformed pose - Blender deforms the mesh by the bone
instead, the rendered result is the same. The current pose is set, and the pose at every frame where the
armature has a key is keyed there, so frame ``f`` renders the pose of frame ``f``. The undeformed pose is the
object's pose with the last applied motion taken off, so changes a script makes to an object between calls stay.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .armature import Armature
from .bone_math import matrix_to_euler
from .types import Entity


class ObjectPoser:
    """The motion last applied to each object (by ``id``), to recover its undeformed pose, and what each object's
    key at each frame was made from (a key made from the same bone poses and undeformed pose is not made again)."""

    def __init__(self) -> None:
        self._applied: dict[int, np.ndarray] = {}
        self._made: dict[tuple[int, int], tuple[int, bytes]] = {}
        self._held: dict[int, dict[str, np.ndarray]] = {}  # keeps the evaluations whose ids ``_made`` holds alive

    def rest_basis(self, obj: Entity) -> np.ndarray:
        """The object's basis (in the robot's frame) without the bone's motion last applied to it."""
        return np.linalg.inv(self._applied.get(id(obj), np.eye(4))) @ obj.basis(None)

    def set_rest_basis(self, obj: Entity, rest: np.ndarray) -> None:
        set_basis(obj, self._applied.get(id(obj), np.eye(4)) @ rest, None)

    def refresh(self, armature: Armature, links: list[Any]) -> None:
        """Pose the objects of ``links`` (:class:`~hybridgen.bproc.urdf_link.Link`) now and at every keyed frame."""
        frames = keyed_frames(armature)
        now = armature.evaluate(None)
        at = {frame: armature.evaluate(frame) for frame in frames}
        self._held.update(at)
        for link in links:
            if link.rig is None:
                continue
            bone = link.rig.deform
            rest_inverse = np.linalg.inv(bone.rest())
            for obj in (o for o in link.get_all_objs() if o.is_valid()):
                rest = self.rest_basis(obj)
                made_from = np.round(rest, 9).tobytes() + np.round(rest_inverse, 9).tobytes()
                for frame in frames:
                    if self._made.get((id(obj), frame)) != (id(at[frame]), made_from):
                        set_basis(obj, at[frame][bone.name] @ rest_inverse @ rest, frame)
                        self._made[(id(obj), frame)] = (id(at[frame]), made_from)
                motion = now[bone.name] @ rest_inverse
                set_basis(obj, motion @ rest, None)
                self._applied[id(obj)] = motion


def keyed_frames(armature: Armature) -> list[int]:
    """Every frame where a bone's pose or a constraint's influence has a key."""
    frames: set[int] = set()
    for bone in armature.bones.values():
        frames.update(bone.location.keys, bone.rotation.keys)
        for constraint in bone.constraints:
            frames.update(getattr(getattr(constraint, "influence", None), "keys", {}))
        if bone.ik is not None:
            frames.update(bone.ik.influence.keys)
    return sorted(frames)


def set_basis(obj: Entity, basis: np.ndarray, frame: int | None) -> None:
    """Set (and at ``frame``, key) an object's location, rotation and scale from a basis matrix."""
    scale = np.linalg.norm(basis[:3, :3], axis=0)
    if np.linalg.det(basis[:3, :3]) < 0:
        scale[0] = -scale[0]
    obj.set_location(basis[:3, 3], frame)
    obj.set_rotation_euler(matrix_to_euler(basis[:3, :3] / scale[None, :]), frame)
    obj.set_scale(scale, frame)
