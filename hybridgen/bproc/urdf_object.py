"""``bproc.types``-style classes of a loaded URDF robot (BlenderProc's URDFObject, Link and Inertial) without
Blender's armature: links are entities at their zero pose holding their visual, collision and inertial objects as
children; the joint-space calls (forward and inverse kinematics, bone controllers) raise one line naming the call.
:func:`hybridgen.bproc.loader_urdf.load_urdf` builds them."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import InputError
from ..io.urdf import Robot
from .types import Entity, MeshObject
from .types.unsupported import unsupported_method


def _urdf_method(name: str) -> Callable[..., Any]:
    return unsupported_method("URDFObject", name, "hybridgen has no armature")


class Inertial(MeshObject):
    """A link's inertial element: a hidden cube with the link's ``mass`` (kg) and 3x3 ``inertia``."""

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


class Link(Entity):
    """A URDF link: its visuals, collisions and inertial (children of it), its joint's type and neighbours."""

    def __init__(self, name: str, local2world: np.ndarray) -> None:
        super().__init__(name, local2world)
        self.visuals: list[MeshObject] = []
        self.collisions: list[MeshObject] = []
        self.inertial: Inertial | None = None
        self.joint_type: str | None = None
        self.joint_name: str | None = None
        self.link_parent: Link | None = None
        self.link_child: Link | None = None

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

    def get_visual_local2world_mats(self, parent2world_matrix: Any = None) -> list[np.ndarray] | None:
        return [v.get_local2world_mat() for v in self.visuals] or None

    def get_collision_local2world_mats(self, parent2world_matrix: Any = None) -> list[np.ndarray] | None:
        return [c.get_local2world_mat() for c in self.collisions] or None

    def get_inertial_local2world_mat(self, parent2world_matrix: Any = None) -> np.ndarray | None:
        return None if self.inertial is None else self.inertial.get_local2world_mat()

    def hide(self, hide_object: bool = True) -> None:
        """Hide the link and its objects."""
        super().hide(hide_object)
        for obj in self.get_all_objs():
            obj.hide(hide_object)

    set_rotation_euler_fk: Callable[..., Any] = unsupported_method("Link", "set_rotation_euler_fk",
                                                                   "hybridgen has no armature")
    set_rotation_euler_ik: Callable[..., Any] = unsupported_method("Link", "set_rotation_euler_ik",
                                                                   "hybridgen has no armature")
    set_location_ik: Callable[..., Any] = unsupported_method("Link", "set_location_ik", "hybridgen has no armature")
    create_ik_bone_controller: Callable[..., Any] = unsupported_method("Link", "create_ik_bone_controller",
                                                                       "hybridgen has no armature")
    get_joint_rotation: Callable[..., Any] = unsupported_method("Link", "get_joint_rotation",
                                                                "hybridgen has no armature")


class URDFObject(Entity):
    """A loaded URDF robot: ``links`` in the file's order (BlenderProc's URDFObject, without its armature)."""

    def __init__(self, name: str, links: list[Link], robot: Robot) -> None:
        super().__init__(name)
        self.links = links
        self.xml_tree = robot
        self.ik_link: Link | None = None

    def get_all_urdf_objs(self) -> list[Entity]:
        return [obj for link in self.links for obj in [link, *link.get_all_objs()]]

    def get_all_collision_objs(self) -> list[MeshObject]:
        return [obj for link in self.links for obj in link.collisions]

    def get_all_inertial_objs(self) -> list[Inertial]:
        return [link.inertial for link in self.links if link.inertial is not None]

    def get_all_visual_objs(self) -> list[MeshObject]:
        return [obj for link in self.links for obj in link.visuals]

    def get_links_with_revolute_joints(self) -> list[Link]:
        return [link for link in self.links if link.joint_type == "revolute"]

    def hide_links_and_collision_inertial_objs(self) -> None:
        """Hide the collision and inertial objects (links have no geometry of their own here)."""
        for link in self.links:
            for obj in link.get_all_objs():
                if "collision" in obj.get_name() or "inertial" in obj.get_name():
                    obj.hide()

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
        """Drop link ``index`` from ``links``. A link with a joint is deleted with its objects, its child chain
        moved by the offset between the two joints' positions (BlenderProc moves the bones' heads so); a link
        without a joint (a 'world' link) only leaves the list, as in BlenderProc."""
        if not 0 <= index < len(self.links):
            raise InputError(f"Invalid index {index}. Index must be in range 0, {len(self.links)} (no. links: "
                             f"{len(self.links)}).")
        removed = self.links.pop(index)
        child = removed.link_child
        if child is None or removed.joint_name is None:
            return
        offset = child.get_local2world_mat()[:3, 3] - removed.get_local2world_mat()[:3, 3]
        chain: Link | None = child
        while chain is not None:
            for obj in chain.get_all_objs():
                obj.set_local2world_mat(_shifted(obj.get_local2world_mat(), -offset))
            chain = chain.link_child
        if removed is self.ik_link:
            self.ik_link = None
        for obj in removed.get_all_objs():
            obj.delete()
        removed.delete()

    def hide(self, hide_object: bool = True) -> None:
        super().hide(hide_object)
        for link in self.links:
            link.hide(hide_object)

    def get_all_local2world_mats(self) -> np.ndarray:
        """(links with a joint, 4, 4): their joint frames in the world."""
        return np.stack([link.get_local2world_mat() for link in self.links if link.joint_name is not None])

    def get_all_visual_local2world_mats(self) -> np.ndarray:
        return np.stack([obj.get_local2world_mat() for obj in self.get_all_visual_objs()])

    def get_all_collision_local2world_mats(self) -> np.ndarray:
        return np.stack([obj.get_local2world_mat() for obj in self.get_all_collision_objs()])

    def get_all_inertial_local2world_mats(self) -> np.ndarray:
        return np.stack([obj.get_local2world_mat() for obj in self.get_all_inertial_objs()])

    set_rotation_euler_fk = _urdf_method("set_rotation_euler_fk")
    set_rotation_euler_ik = _urdf_method("set_rotation_euler_ik")
    set_location_ik = _urdf_method("set_location_ik")
    create_ik_bone_controller = _urdf_method("create_ik_bone_controller")
    has_reached_ik_pose = _urdf_method("has_reached_ik_pose")


def _shifted(matrix: np.ndarray, delta: np.ndarray) -> np.ndarray:
    moved = matrix.copy()
    moved[:3, 3] += delta
    return moved
