"""``bproc.types.URDFObject``: a loaded URDF robot with BlenderProc's armature (its URDFUtility), built by
:func:`hybridgen.bproc.loader_urdf.load_urdf`.

The robot is an entity (BlenderProc's armature object) that parents its links and their objects; moving it moves
the whole robot. Its joints' bones (:mod:`hybridgen.bproc.urdf_rig`) are posed by forward kinematics
(``set_rotation_euler_fk``: one link, or every revolute joint when ``link`` is None) or inverse kinematics
(``create_ik_bone_controller`` then ``set_location_ik`` / ``set_rotation_euler_ik``), each call keying the
bones at ``frame`` (BlenderProc's ``_set_keyframe``: the frame range grows by one when ``frame`` is past its
end). After every change each link's visual, collision and inertial objects are posed by their joint's deform
bone - the current pose and the pose at every keyed frame - so that frame ``f`` renders the pose keyed at ``f``
in color and labels. ``get_all_local2world_mats`` gives each jointed link's deform bone pose (4x4, world, m;
the bone's Y axis along the joint axis, as Blender's bones), ``frame`` (hybridgen's addition) the pose keyed
there. ``has_reached_ik_pose`` compares the IK constraint bone and the controller now with their offset when the
controller was made (metres, radians).
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator

import numpy as np

from ..errors import InputError
from ..io.urdf import Robot
from ..logs import log_line
from .armature import Armature
from .bone import Bone
from .bone_math import quaternion_angle
from .session import SESSION
from .types import Entity, MeshObject
from .urdf_link import Inertial, Link
from .urdf_poser import ObjectPoser
from .urdf_rig import SCENE_FRAME

__all__ = ["Inertial", "Link", "URDFObject"]


class URDFObject(Entity):
    """A loaded URDF robot: ``links`` in the file's order (module documentation)."""

    def __init__(self, name: str, links: list[Link], robot: Robot, armature: Armature | None = None) -> None:
        super().__init__(name)
        self.links = links
        self.xml_tree = robot
        self.armature = armature if armature is not None else Armature()
        self.all_links: list[Link] = list(links)
        self.fk_ik_mode: str | None = None
        self.ik_link: Link | None = None
        self.ik_constraint_bone: Bone | None = None
        self.ik_controller_bone: Bone | None = None
        self.ik_bone_offset: np.ndarray | None = None
        self._poser = ObjectPoser()
        self._batch = 0

    @contextmanager
    def _batched(self) -> Iterator[None]:
        """Changes inside pose the objects once, at the end."""
        self._batch += 1
        try:
            yield
        finally:
            self._batch -= 1
        self.refresh_objects()

    # --- parts --------------------------------------------------------------------------------------------
    def get_all_urdf_objs(self) -> list[Entity]:
        return [obj for link in self.links for obj in [link, *link.get_all_objs()]]

    def get_all_collision_objs(self) -> list[MeshObject]:
        return [obj for obj in self.get_all_urdf_objs() if "collision" in obj.get_name()]

    def get_all_inertial_objs(self) -> list[Inertial]:
        return [obj for obj in self.get_all_urdf_objs() if isinstance(obj, Inertial)]

    def get_all_visual_objs(self) -> list[MeshObject]:
        return [obj for obj in self.get_all_urdf_objs() if "visual" in obj.get_name()]

    def get_links_with_revolute_joints(self) -> list[Link]:
        return [link for link in self.links if link.joint_type == "revolute"]

    def hide_links_and_collision_inertial_objs(self) -> None:
        """Hide the collision and inertial objects (links have no geometry of their own here)."""
        for link in self.links:
            for obj in link.get_all_objs():
                if "collision" in obj.get_name() or "inertial" in obj.get_name():
                    obj.hide()

    def hide(self, hide_object: bool = True) -> None:
        super().hide(hide_object)
        for link in self.links:
            link.hide(hide_object)

    def set_ascending_category_ids(self, category_ids: list[int] | None = None) -> None:
        """``category_id`` 1, 2, ... (or ``category_ids``) for the links and their objects, in link order."""
        ids = list(range(1, len(self.links) + 1)) if category_ids is None else list(category_ids)
        if len(ids) != len(self.links):
            raise InputError(f"Need equal amount of category ids for links. Got {len(ids)} and {len(self.links)}, "
                             "respectively.")
        for link, category_id in zip(self.links, ids):
            link.set_cp("category_id", category_id)
            for obj in link.get_all_objs():
                obj.set_cp("category_id", category_id)

    def remove_link_by_index(self, index: int = 0) -> None:
        """Drop link ``index`` from ``links``. When it has a joint and a child, its objects and itself are
        deleted and the child's chain (bones and objects) moves by the offset between the two joints, so the
        child takes its place (rotations unchanged); a link without a joint only leaves the list, as in
        BlenderProc."""
        if not 0 <= index < len(self.links):
            raise InputError(f"Invalid index {index}. Index must be in range 0, {len(self.links)} (no. links: "
                             f"{len(self.links)}).")
        removed = self.links.pop(index)
        child = removed.link_child
        if child is None or removed.rig is None:
            return
        offset = (child.rig.deform.head if child.rig is not None else child.basis(None)[:3, 3]) \
            - removed.rig.deform.head
        self.armature.reset_to_frame(SCENE_FRAME)  # BlenderProc edits the bones in edit mode
        chain: Link | None = child
        while chain is not None:
            for bone in chain.rig.bones() if chain.rig is not None else []:
                bone.head, bone.tail = bone.head - offset, bone.tail - offset
            for obj in chain.get_all_objs():
                rest = self._poser.rest_basis(obj)
                rest[:3, 3] -= offset
                self._poser.set_rest_basis(obj, rest)
            chain = chain.link_child
        if removed is self.ik_link:
            self.ik_link = None
        for obj in removed.get_all_objs():
            obj.delete()
        removed.delete()
        self.refresh_objects()

    # --- poses --------------------------------------------------------------------------------------------
    def _poses(self, frame: int | None) -> dict[str, np.ndarray]:
        if frame is None:
            self.armature.update()
            return self.armature.evaluated
        return self.armature.evaluate(frame)

    def get_all_local2world_mats(self, frame: int | None = None) -> np.ndarray:
        """(links with a joint, 4, 4): their deform bones' poses in the world (m)."""
        poses, world = self._poses(frame), self.world_matrix(frame)
        return np.stack([world @ poses[link.rig.deform.name] for link in self.links if link.rig is not None])

    def _stacked(self, kind: str, frame: int | None) -> np.ndarray:
        world = self.world_matrix(frame)
        per_link = [getattr(link, f"get_{kind}_local2world_mat{'' if kind == 'inertial' else 's'}")(world, frame)
                    for link in self.links]
        missing = [link.get_name() for link, mats in zip(self.links, per_link) if mats is None]
        if missing:
            raise InputError(f"bproc.types.URDFObject.get_all_{kind}_local2world_mats: link(s) {missing} have no "
                             f"{kind} (BlenderProc cannot stack them either)")
        return np.stack([np.asarray(mats) for mats in per_link])

    def get_all_visual_local2world_mats(self, frame: int | None = None) -> np.ndarray:
        """(links, visuals per link, 4, 4): every link's visuals posed by its bone (m, world)."""
        return self._stacked("visual", frame)

    def get_all_collision_local2world_mats(self, frame: int | None = None) -> np.ndarray:
        return self._stacked("collision", frame)

    def get_all_inertial_local2world_mats(self, frame: int | None = None) -> np.ndarray:
        return self._stacked("inertial", frame)

    # --- the objects following the bones ------------------------------------------------------------------
    def refresh_objects(self) -> None:
        """Pose every link's objects by its deform bone: now, and at every keyed frame (module documentation)."""
        if not self._batch:
            self._poser.refresh(self.armature, self.all_links)

    # --- joint space --------------------------------------------------------------------------------------
    def _switch_fk_ik_mode(self, mode: str = "fk", keep_pose: bool = True) -> None:
        if mode == "ik" and self.ik_controller_bone is None:
            raise InputError("bproc.types.URDFObject: no IK bone controller; set one up first with "
                             "create_ik_bone_controller()")
        if self.fk_ik_mode != mode:
            for link in self.links:
                link.switch_fk_ik_mode(mode, keep_pose)
            self.fk_ik_mode = mode

    def _set_keyframe(self, name: str, frame: int) -> None:
        """Key ``name`` (``rotation_euler`` or ``location``) of the robot and its bones at ``frame``."""
        self.armature.update()
        own = self._rotation if name == "rotation_euler" else self._location
        own.set(own.value, int(frame))
        bones: list[Bone] = []
        for link in self.links:
            if link.rig is not None:
                bones.extend(link.rig.bones())
                for constraint in (link.rig.deform.copy_rotation(n) for n in ("copy_rotation.fk", "copy_rotation.ik")):
                    if constraint is not None and link.joint_type == "revolute":
                        constraint.influence.set(constraint.influence.value, int(frame))
        bones += [b for b in (self.ik_constraint_bone, self.ik_controller_bone) if b is not None]
        for bone in bones:
            value = bone.rotation if name == "rotation_euler" else bone.location
            value.set(value.value, int(frame))
        if int(frame) > SESSION.frame_end:
            SESSION.frame_end += 1

    def set_rotation_euler_fk(self, link: Link | None, rotation_euler: Any, mode: str = "absolute",
                              frame: int = 0) -> None:
        """Rotate ``link``'s joint, or every revolute joint (one angle each, or a list with one per joint), in
        FK mode; keyed at ``frame``."""
        with self._batched():
            self._switch_fk_ik_mode("fk")
            if link is not None:
                link.set_rotation_euler_fk(rotation_euler, mode)
            else:
                revolute = self.get_links_with_revolute_joints()
                if isinstance(rotation_euler, list) and len(rotation_euler) == len(revolute):
                    for joint_link, rotation in zip(revolute, rotation_euler):
                        joint_link.set_rotation_euler_fk(rotation, mode)
                else:
                    for joint_link in revolute:
                        joint_link.set_rotation_euler_fk(rotation_euler, mode)
            self._set_keyframe("rotation_euler", frame)

    def create_ik_bone_controller(self, link: Link | None = None, relative_location: Any = None,
                                  use_rotation: bool = True, chain_length: int = 0) -> None:
        """Set up IK for ``link`` (default: the last), its point of control ``relative_location`` (m, armature
        axes) from its joint; ``chain_length`` parent bones move (0: all); ``use_rotation``: the link turns too."""
        if self.ik_controller_bone is not None:
            raise InputError("bproc.types.URDFObject.create_ik_bone_controller: the robot already has an IK "
                             "controller; more than one is not supported (as in BlenderProc)")
        link = self.links[-1] if link is None else link
        with self._batched():
            constraint, controller, offset = link.create_ik_bone_controller(relative_location, use_rotation,
                                                                            chain_length)
            self.ik_constraint_bone, self.ik_controller_bone, self.ik_bone_offset = constraint, controller, offset
            self.ik_link = link
            self._switch_fk_ik_mode("ik")

    def _ik_link(self, call: str) -> Link:
        self._switch_fk_ik_mode("ik")
        if self.ik_link is None:
            raise InputError(f"bproc.types.URDFObject.{call}: the robot has no IK link")
        return self.ik_link

    def set_rotation_euler_ik(self, rotation_euler: Any, mode: str = "absolute", frame: int = 0) -> None:
        """Rotate the IK controller (XYZ angles, rad), keyed at ``frame``."""
        with self._batched():
            self._ik_link("set_rotation_euler_ik").set_rotation_euler_ik(rotation_euler, mode)
            self._set_keyframe("rotation_euler", frame)

    def set_location_ik(self, location: Any, frame: int = 0) -> None:
        """Ask the IK link's joint to reach ``location`` (m, armature frame), keyed at ``frame``."""
        with self._batched():
            self._ik_link("set_location_ik").set_location_ik(location)
            self._set_keyframe("location", frame)

    def has_reached_ik_pose(self, location_error: float = 0.01, rotation_error: float = 0.01) -> bool:
        """Whether the IK chain reached the controller: translation (m) and rotation (rad) differences from the
        offset they had when it was made, each below its tolerance."""
        if self.ik_constraint_bone is None or self.ik_controller_bone is None or self.ik_bone_offset is None:
            raise InputError("bproc.types.URDFObject.has_reached_ik_pose: no IK bone controller; call "
                             "create_ik_bone_controller() first")
        current = np.linalg.inv(self.armature.pose(self.ik_constraint_bone.name)) \
            @ self.armature.pose(self.ik_controller_bone.name)
        moved = float(np.linalg.norm(current[:3, 3] - self.ik_bone_offset[:3, 3]))
        turned = quaternion_angle(current[:3, :3].T @ self.ik_bone_offset[:3, :3])
        reached = moved < location_error and turned < rotation_error
        log_line(f"IK pose {'is' if reached else 'is not'} within the given constraints: translation difference "
                 f"{moved:.4f} (max: {location_error}), rotation difference {turned:.4f} (max: {rotation_error})")
        return reached

