"""``bproc.types.Entity``: a Blender object with a keyframable pose and a parent (BlenderProc's EntityUtility).

The pose is Blender's: ``location`` (m), ``rotation_euler`` (rad, Blender ``XYZ``: ``R = Rz @ Ry @ Rx``) and
``scale`` compose the basis ``T @ R @ S``; with a parent, ``matrix_world = parent.matrix_world @
matrix_parent_inverse @ basis``, where ``set_parent`` stores the inverse of the parent's pose at that moment so the
child stays where it is (Blender's "Object, keep transform"). Each of the three is an
:class:`~hybridgen.bproc.session.Animated` property: a ``frame`` argument keys it, and a render of frame ``f``
sees the keyed values (:meth:`Entity.world_matrix`).
"""
from __future__ import annotations

import copy
from typing import Any, Sequence

import numpy as np

from ...errors import InputError
from ...scene.frames import euler_xyz_to_matrix, matrix_to_euler_xyz
from ..session import SESSION, Animated
from .struct import Struct


def vector3(value: Any, what: str) -> np.ndarray:
    """A finite 3-vector as float64 (one line naming ``what`` otherwise)."""
    array = np.array(value, dtype=np.float64).reshape(-1)  # a copy: the caller may change its array later
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise InputError(f"{what} must be 3 finite numbers, got {np.asarray(value).tolist()}")
    return array


def matrix4(value: Any, what: str) -> np.ndarray:
    """A finite 4x4 matrix as float64 (a copy: the caller may change its array later)."""
    array = np.array(value, dtype=np.float64)
    if array.shape != (4, 4) or not np.all(np.isfinite(array)):
        raise InputError(f"{what} must be a finite 4x4 matrix, got shape {array.shape}")
    return array


def compose(location: np.ndarray, rotation_euler: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Blender's basis matrix ``T(location) @ R(rotation_euler) @ S(scale)``."""
    matrix = np.eye(4)
    matrix[:3, :3] = euler_xyz_to_matrix(rotation_euler) * np.asarray(scale)[None, :]
    matrix[:3, 3] = location
    return matrix


def decompose(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(location, rotation_euler, scale) of an affine 4x4 as Blender decomposes ``matrix_world``: scale = column
    lengths (negative for a mirroring matrix, on x), rotation = the columns divided by them."""
    linear = matrix[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale <= 0):
        raise InputError("a pose matrix with a zero-length axis has no rotation")
    if np.linalg.det(linear) < 0:
        scale[0] = -scale[0]
    return matrix[:3, 3].copy(), matrix_to_euler_xyz(linear / scale[None, :]), scale


class Entity(Struct):
    """A Blender object: pose, parent, visibility. ``KIND`` ``object``: names are unique among all objects."""

    KIND = "object"
    ATTRIBUTES = ("name", "location", "rotation_euler", "scale", "matrix_world", "type", "hide_render")
    TYPE = "EMPTY"

    def __init__(self, name: str, local2world: np.ndarray | None = None) -> None:
        super().__init__(name)
        location, rotation, scale = decompose(np.eye(4) if local2world is None else matrix4(local2world, "pose"))
        self._location, self._rotation, self._scale = Animated(location), Animated(rotation), Animated(scale)
        self._parent: Entity | None = None
        self._parent_inverse = np.eye(4)
        self._hidden = False
        SESSION.entities.append(self)

    # --- pose ---------------------------------------------------------------------------------------------
    def set_location(self, location: Sequence[float], frame: int | None = None) -> None:
        """Location in the parent's frame (the world without a parent), metres; keyed at ``frame`` if given."""
        self._location.set(vector3(location, "location"), frame)

    def set_rotation_euler(self, rotation_euler: Sequence[float], frame: int | None = None) -> None:
        """Blender ``XYZ`` Euler angles, radians; keyed at ``frame`` if given."""
        self._rotation.set(vector3(rotation_euler, "rotation_euler"), frame)

    def set_rotation_mat(self, rotation_mat: Any, frame: int | None = None) -> None:
        """The rotation as a 3x3 matrix (stored as its Euler angles)."""
        self._rotation.set(matrix_to_euler_xyz(np.asarray(rotation_mat, dtype=np.float64)[:3, :3]), frame)

    def set_scale(self, scale: Sequence[float], frame: int | None = None) -> None:
        self._scale.set(vector3(scale, "scale"), frame)

    def get_location(self, frame: int | None = None) -> np.ndarray:
        return np.array(self._location.at(frame))

    def get_rotation_euler(self, frame: int | None = None) -> np.ndarray:
        return np.array(self._rotation.at(frame))

    def get_rotation(self, frame: int | None = None) -> np.ndarray:
        """BlenderProc's older name of :meth:`get_rotation_euler`."""
        return self.get_rotation_euler(frame)

    def get_rotation_mat(self, frame: int | None = None) -> np.ndarray:
        return euler_xyz_to_matrix(self._rotation.at(frame))

    def get_scale(self, frame: int | None = None) -> np.ndarray:
        return np.array(self._scale.at(frame))

    def basis(self, frame: int | None = None) -> np.ndarray:
        """Blender's ``matrix_basis`` at ``frame`` (None: the current values)."""
        return compose(self._location.at(frame), self._rotation.at(frame), self._scale.at(frame))

    def world_matrix(self, frame: int | None = None) -> np.ndarray:
        """``matrix_world`` (local -> world, metres) at ``frame``, through every parent."""
        if self._parent is None:
            return self.basis(frame)
        return self._parent.world_matrix(frame) @ self._parent_inverse @ self.basis(frame)

    def get_local2world_mat(self) -> np.ndarray:
        """The current 4x4 local2world."""
        return self.world_matrix(None)

    def set_local2world_mat(self, matrix_world: Any) -> None:
        """Set the pose so that ``matrix_world`` becomes this 4x4 (the basis is solved through the parent)."""
        target = matrix4(matrix_world, "matrix_world")
        if self._parent is not None:
            target = np.linalg.inv(self._parent.world_matrix(None) @ self._parent_inverse) @ target
        location, rotation, scale = decompose(target)
        self._location.set(location)
        self._rotation.set(rotation)
        self._scale.set(scale)

    def apply_T(self, transform: Any) -> None:  # noqa: N802 - BlenderProc's name
        """Right-multiply the pose by ``transform`` (in the object's own frame)."""
        self.set_local2world_mat(self.get_local2world_mat() @ matrix4(transform, "transform"))

    # --- hierarchy ----------------------------------------------------------------------------------------
    def set_parent(self, new_parent: "Entity") -> None:
        """Parent this object to ``new_parent``, keeping its world pose."""
        if self._parent is not None:
            self.clear_parent()
        ancestor: Entity | None = new_parent
        while ancestor is not None:
            if ancestor is self:
                raise InputError(f"'{self.get_name()}' cannot be a parent of itself (loop in the hierarchy)")
            ancestor = ancestor._parent
        self._parent = new_parent
        self._parent_inverse = np.linalg.inv(new_parent.get_local2world_mat())

    def clear_parent(self) -> None:
        """Move the object to the root, keeping its world pose."""
        pose = self.get_local2world_mat()
        self._parent, self._parent_inverse = None, np.eye(4)
        self.set_local2world_mat(pose)

    def get_parent(self) -> "Entity | None":
        return self._parent

    def get_children(self, return_all_offspring: bool = False) -> list["Entity"]:
        children = [e for e in SESSION.entities if e._parent is self]
        if return_all_offspring:
            for child in list(children):
                children.extend(child.get_children(True))
        return children

    # --- life cycle and visibility ------------------------------------------------------------------------
    def duplicate(self, duplicate_children: bool = True, linked: bool = False) -> "Entity":
        """A copy named ``<name>.001`` (Blender's next free suffix) at the same pose; ``linked`` shares the mesh
        data (hybridgen never edits it in place, so both are the same here). Children are copied under it."""
        twin = copy.copy(self)
        twin._copy_state_from(self)
        if duplicate_children:
            for child in self.get_children():
                child_twin = child.duplicate(True, linked)
                child_twin._parent, child_twin._parent_inverse = twin, child._parent_inverse.copy()
        return twin

    def _copy_state_from(self, other: "Entity") -> None:
        """Give this shallow copy of ``other`` its own name, properties and pose (subclasses copy more)."""
        self._name = SESSION.claim_name(self.KIND, other.get_name())
        self._cps = {key: copy.deepcopy(prop) for key, prop in other._cps.items()}
        self._location, self._rotation, self._scale = (copy.deepcopy(p) for p in
                                                       (other._location, other._rotation, other._scale))
        self._valid = True
        SESSION.entities.append(self)

    def delete(self, remove_all_offspring: bool = False) -> None:
        """Remove the object from the scene (children kept at their world pose unless removed too)."""
        doomed = [self] + (self.get_children(True) if remove_all_offspring else [])
        for entity in doomed:
            for child in entity.get_children():
                if child not in doomed:
                    child.clear_parent()
        for entity in doomed:
            if entity in SESSION.entities:
                SESSION.entities.remove(entity)
            entity._invalidate()

    def is_empty(self) -> bool:
        return self.TYPE == "EMPTY"

    def hide(self, hide_object: bool = True) -> None:
        """Hide the object in renders (Blender's ``hide_render``)."""
        self._hidden = bool(hide_object)

    def is_hidden(self) -> bool:
        return self._hidden

    def select(self) -> None:
        """Blender's selection state: it changes no output, so nothing to do."""

    def deselect(self) -> None:
        """See :meth:`select`."""

    def clear_keyframes(self) -> None:
        super().clear_keyframes()
        for prop in (self._location, self._rotation, self._scale):
            prop.keys.clear()

    def _attribute(self, attr_name: str) -> Any:
        values = {"location": self.get_location, "rotation_euler": self.get_rotation_euler, "scale": self.get_scale,
                  "matrix_world": self.get_local2world_mat}
        if attr_name in values:
            return values[attr_name]()
        return {"type": self.TYPE, "hide_render": self._hidden}.get(attr_name, self.get_name())

    def __eq__(self, other: object) -> bool:
        return self is other

    def __hash__(self) -> int:
        return id(self)
