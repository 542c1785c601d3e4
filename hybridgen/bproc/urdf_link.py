"""``bproc.types.Link`` and ``Inertial``: one link of a loaded URDF robot (BlenderProc's LinkUtility).

A link is a mesh object without geometry that stays at its zero pose (BlenderProc's link objects are moved by
their armature's deformation, not by their own pose); its visual, collision and inertial objects follow its
joint's deform bone (:mod:`hybridgen.bproc.urdf_rig`), keyed per frame by its robot
(:mod:`hybridgen.bproc.urdf_object`). Its joint's bones are ``rig`` (None for the root link). Joint-space calls
act on those bones as BlenderProc's do: FK sets the FK bone's Euler angles (absolute ones clipped to the joint's
limits), IK moves the IK controller bone (``create_ik_bone_controller``), and ``switch_fk_ik_mode`` hands the
link's deform bone from one chain to the other, the new chain taking the old one's pose. Matrices are 4x4,
metres, world frame unless said otherwise.
"""
from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from ..errors import InputError
from .armature import Armature
from .bone import Bone
from .bone_math import quaternion_angle
from ..scene.primitives import make_primitive
from .types import MeshObject
from .urdf_rig import RigJoint, add_ik_controller, set_bone_rotation


class RobotOwner(Protocol):
    """What a link needs of its robot (:class:`hybridgen.bproc.urdf_object.URDFObject`)."""

    def refresh_objects(self) -> None: ...

    def world_matrix(self, frame: int | None = None) -> np.ndarray: ...


class Inertial(MeshObject):
    """A link's inertial element: a hidden 3 cm cube at the link's frame with the link's ``mass`` (kg), 3x3
    ``inertia`` (kg m^2) and the URDF's inertial ``origin`` (4x4, link frame; kept, not applied, as in
    BlenderProc)."""

    def __init__(self, name: str, parts: list[Any], mass: float, inertia: np.ndarray, origin: np.ndarray) -> None:
        super().__init__(name, parts)
        self._mass, self._inertia, self._origin_mat = float(mass), np.array(inertia), np.array(origin)

    def get_mass(self) -> float:
        return self._mass

    def set_mass(self, mass: float) -> None:
        self._mass = float(mass)

    def get_inertia(self) -> np.ndarray:
        return self._inertia.copy()

    def set_inertia(self, inertia: Any) -> None:
        self._inertia = np.asarray(inertia, dtype=np.float64).reshape(3, 3)

    def get_origin(self) -> np.ndarray:
        return self._origin_mat.copy()

    def set_origin(self, origin: Any) -> None:
        self._origin_mat = np.asarray(origin, dtype=np.float64).reshape(4, 4)


class Link(MeshObject):
    """A URDF link (module documentation): a mesh object without geometry, as BlenderProc's."""

    def __init__(self, name: str, local2world: np.ndarray) -> None:
        super().__init__(name, [make_primitive("cube", 1.0)], local2world=local2world)
        self.parts, self.part_slots = [], []
        self.visuals: list[MeshObject] = []
        self.collisions: list[MeshObject] = []
        self.inertial: Inertial | None = None
        self.joint_type: str | None = None
        self.joint_name: str | None = None
        self.link_parent: Link | None = None
        self.link_child: Link | None = None
        self.rig: RigJoint | None = None
        self.armature: Armature | None = None
        self.owner: RobotOwner | None = None
        self.fk_ik_mode = "fk"
        self.ik_bone_controller: Bone | None = None
        self.ik_bone_constraint: Bone | None = None
        self.link2bone_mat: np.ndarray | None = None
        self.visual_local2link_mats: list[np.ndarray] = []
        self.collision_local2link_mats: list[np.ndarray] = []
        self.inertial_local2link_mat: np.ndarray | None = None

    # --- parts --------------------------------------------------------------------------------------------
    def get_visuals(self) -> list[MeshObject]:
        return list(self.visuals)

    def get_collisions(self) -> list[MeshObject]:
        return list(self.collisions)

    def get_inertial(self) -> Inertial | None:
        return self.inertial

    def get_all_objs(self) -> list[MeshObject]:
        """Visuals, collisions and the inertial."""
        return self.visuals + self.collisions + ([self.inertial] if self.inertial is not None else [])

    def get_joint_type(self) -> str | None:
        return self.joint_type

    def get_link_parent(self) -> "Link | None":
        return self.link_parent

    def get_link_child(self) -> "Link | None":
        return self.link_child

    def get_fk_ik_mode(self) -> str:
        return self.fk_ik_mode

    @property
    def bone(self) -> Bone | None:
        """The joint's deform bone (BlenderProc's ``link.bone``)."""
        return None if self.rig is None else self.rig.deform

    def mesh_as_trimesh(self) -> Any:
        """The first visual as a ``trimesh.Trimesh`` (None without visuals)."""
        return self.visuals[0].mesh_as_trimesh() if self.visuals else None

    def hide(self, hide_object: bool = True) -> None:
        """Hide the link and its objects."""
        super().hide(hide_object)
        for obj in self.get_all_objs():
            obj.hide(hide_object)

    def set_rotation_euler(self, *_args: Any, **_kwargs: Any) -> None:
        raise InputError("bproc.types.Link.set_rotation_euler: use set_rotation_euler_fk() or "
                         "set_rotation_euler_ik(), as in BlenderProc")

    def set_location(self, *_args: Any, **_kwargs: Any) -> None:
        raise InputError("bproc.types.Link.set_location: use set_location_ik(), as in BlenderProc")

    # --- poses --------------------------------------------------------------------------------------------
    def _poses(self, frame: int | None) -> dict[str, np.ndarray]:
        """Bone poses at ``frame``; None: the current values, evaluated now (BlenderProc updates first)."""
        assert self.armature is not None
        if frame is None:
            self.armature.update()
            return self.armature.evaluated
        return self.armature.evaluate(frame)

    def _part_mats(self, mats: list[np.ndarray], parent2world_matrix: Any, frame: int | None) -> list[np.ndarray]:
        armature_world = (self.owner.world_matrix(frame) if self.owner is not None else np.eye(4)) \
            if parent2world_matrix is None else np.asarray(parent2world_matrix, dtype=np.float64)
        if self.rig is None or self.armature is None or self.link2bone_mat is None:
            return [armature_world @ self.basis(frame) @ m for m in mats]
        deform = self._poses(frame)[self.rig.deform.name] @ np.linalg.inv(self.link2bone_mat)
        return [armature_world @ deform @ m for m in mats]

    def get_visual_local2world_mats(self, parent2world_matrix: Any = None,
                                    frame: int | None = None) -> list[np.ndarray] | None:
        """Each visual's pose from its bone (None without visuals); ``frame``: hybridgen's, the pose keyed there."""
        return self._part_mats(self.visual_local2link_mats, parent2world_matrix, frame) if self.visuals else None

    def get_collision_local2world_mats(self, parent2world_matrix: Any = None,
                                       frame: int | None = None) -> list[np.ndarray] | None:
        if not self.collisions:
            return None
        return self._part_mats(self.collision_local2link_mats, parent2world_matrix, frame)

    def get_inertial_local2world_mat(self, parent2world_matrix: Any = None,
                                     frame: int | None = None) -> np.ndarray | None:
        if self.inertial is None or self.inertial_local2link_mat is None:
            return None
        return self._part_mats([self.inertial_local2link_mat], parent2world_matrix, frame)[0]

    def get_joint_rotation(self, frame: int | None = None) -> float:
        """The angle (rad, 0..pi) the joint's deform bone is turned from its rest pose relative to its parent."""
        if self.rig is None or self.armature is None:
            return 0.0
        poses = self.armature.evaluated if frame is None else self.armature.evaluate(frame)
        bone = self.rig.deform
        relative = np.linalg.inv(bone.rest()) @ poses[bone.name]
        if bone.parent is not None:
            relative = np.linalg.inv(bone.rest()) @ bone.parent.rest() @ np.linalg.inv(poses[bone.parent.name]) \
                @ poses[bone.name]
        return quaternion_angle(relative)

    # --- joint space --------------------------------------------------------------------------------------
    def _changed(self) -> None:
        if self.owner is not None:
            self.owner.refresh_objects()

    def _need_rig(self, call: str) -> tuple[RigJoint, Armature]:
        if self.rig is None or self.armature is None:
            raise InputError(f"bproc.types.Link.{call}: link '{self.get_name()}' has no joint to move")
        return self.rig, self.armature

    def switch_fk_ik_mode(self, mode: str = "fk", keep_pose: bool = True) -> None:
        """Hand the deform bone to the FK or IK chain (module documentation)."""
        if mode not in ("fk", "ik"):
            raise InputError(f"bproc.types.Link.switch_fk_ik_mode: mode must be 'fk' or 'ik', got {mode!r}")
        if self.rig is None or self.armature is None or self.fk_ik_mode == mode:
            return
        rig, armature = self.rig, self.armature
        armature.update()
        source, target = (rig.ik, rig.fk) if mode == "fk" else (rig.fk, rig.ik)
        if keep_pose:
            armature.set_pose_matrix(target, armature.pose(source.name))
        copies = {c.name: c for c in (rig.deform.copy_rotation(n) for n in ("copy_rotation.fk", "copy_rotation.ik"))
                  if c is not None}
        if rig.type == "revolute":
            copies["copy_rotation.fk"].influence.set(1.0 if mode == "fk" else 0.0)
            copies["copy_rotation.ik"].influence.set(0.0 if mode == "fk" else 1.0)
        self.fk_ik_mode = mode
        if mode == "fk":
            if "copy_rotation.ik" in copies:
                copies["copy_rotation.ik"].influence.set(0.0)
            if self.ik_bone_controller is not None and self.ik_bone_constraint is not None:
                assert self.ik_bone_constraint.ik is not None
                self.ik_bone_constraint.ik.influence.set(0.0)
        else:
            if self.ik_bone_controller is not None:
                armature.update()
                self.set_location_ik(armature.pose(rig.deform.name)[:3, 3])
            if self.ik_bone_constraint is not None and self.ik_bone_controller is not None:
                assert self.ik_bone_constraint.ik is not None
                self.ik_bone_constraint.ik.influence.set(1.0)
                pose = armature.pose(rig.fk.name).copy()  # both as last evaluated, as BlenderProc reads them
                pose[:3, 3] = armature.pose(self.ik_bone_controller.name)[:3, 3]
                armature.set_pose_matrix(self.ik_bone_controller, pose)
        self._changed()

    def _rotate(self, chain: str, rotation_euler: Any, mode: str) -> None:
        rig, _ = self._need_rig(f"set_rotation_euler_{chain}")
        if self.fk_ik_mode != chain:
            self.switch_fk_ik_mode(chain)
        bone = rig.fk if chain == "fk" else self.ik_bone_controller
        if bone is None:
            raise InputError("bproc.types.Link.set_rotation_euler_ik: no IK controller; call "
                             "create_ik_bone_controller() first")
        set_bone_rotation(bone, rotation_euler, mode, f"bproc.types.Link.set_rotation_euler_{chain}")
        self._changed()

    def set_rotation_euler_fk(self, rotation_euler: Any, mode: str = "absolute") -> None:
        """Rotate the joint's FK bone: one angle about the joint axis or XYZ angles (rad)."""
        self._rotate("fk", rotation_euler, mode)

    def set_rotation_euler_ik(self, rotation_euler: Any, mode: str = "absolute") -> None:
        """Rotate the IK controller bone (XYZ angles, rad, about its rest axes)."""
        self._rotate("ik", rotation_euler, mode)

    def set_location_ik(self, location: Any) -> None:
        """Move the IK controller so that the link's joint is asked to reach ``location`` (armature space, m);
        the controller's rotation is reset."""
        rig, armature = self._need_rig("set_location_ik")
        if self.fk_ik_mode != "ik":
            self.switch_fk_ik_mode("ik")
        controller = self.ik_bone_controller
        if controller is None:
            raise InputError("bproc.types.Link.set_location_ik: no IK controller; call create_ik_bone_controller() "
                             "first")
        controller.location.set(np.zeros(3))
        controller.rotation.set(np.zeros(3))
        armature.update()
        wanted = np.asarray(location, dtype=np.float64).reshape(3) + (armature.pose(rig.ik.name)[:3, 3]
                                                                      - armature.pose(rig.deform.name)[:3, 3])
        local = np.linalg.inv(armature.pose(controller.name)) @ np.append(wanted, 1.0)
        controller.location.set(local[:3])
        self._changed()

    def create_ik_bone_controller(self, relative_location: Any = None, use_rotation: bool = True,
                                  chain_length: int = 0) -> tuple[Bone, Bone, np.ndarray]:
        """Add the link's IK controller and constraint bones; (constraint bone, controller bone, the controller's
        pose in the constraint bone's frame)."""
        rig, armature = self._need_rig("create_ik_bone_controller")
        constraint, controller = add_ik_controller(armature, rig, [0.0, 0.0, 0.0] if relative_location is None
                                                   else relative_location, use_rotation, chain_length)
        self.ik_bone_constraint, self.ik_bone_controller = constraint, controller
        armature.update()
        offset = np.linalg.inv(armature.pose(constraint.name)) @ armature.pose(controller.name)
        self._changed()
        return constraint, controller, offset

