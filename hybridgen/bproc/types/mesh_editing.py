"""Mesh edits of a ``bproc.types.MeshObject`` (BlenderProc's MeshObjectUtility): texture coordinates by projection
(``add_uv_mapping``) and joining other objects into this one (``join_with_other_objects``, Blender's
``object.join``).

Frames: parts hold vertices in the object's local frame (metres); a joined object's parts are moved from its local
frame into this object's through both world poses.
"""
from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np

from ...errors import InputError
from ...scene.mesh_object import MeshObject as ScenePart
from .unsupported import unsupported_method

if TYPE_CHECKING:
    from .material import Material


def transformed_part(part: ScenePart, matrix: np.ndarray) -> ScenePart:
    """A copy of ``part`` with its vertices (and vertex normals) moved by the 4x4 ``matrix``."""
    linear = matrix[:3, :3]
    twin = copy.copy(part)
    twin.forget_derived()
    twin.vertices = part.vertices @ linear.T + matrix[:3, 3]
    if part.vertex_normals is not None:
        normals = part.vertex_normals @ np.linalg.inv(linear)
        twin.vertex_normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    return twin


class MeshEditing:
    """Mixin of :class:`~hybridgen.bproc.types.MeshObject`: needs ``parts``, ``part_slots``, ``_slots``,
    ``local_mesh``, ``has_uv_mapping`` and the pose."""

    parts: list[ScenePart]
    part_slots: list[int]
    _slots: list["Material | None"]
    local_mesh: Callable[[], tuple[np.ndarray, np.ndarray]]
    has_uv_mapping: Callable[[], bool]
    get_local2world_mat: Callable[[], np.ndarray]
    delete: Callable[..., None]

    def add_uv_mapping(self, projection: str, overwrite: bool = False) -> None:
        """Texture coordinates by Blender's ``cube``, ``cylinder`` or ``sphere`` projection of all faces
        (:mod:`hybridgen.scene.uv_projection`; the pose's rotation and scale now orient the cylinder and sphere),
        unless the object has coordinates already and not ``overwrite``. ``smart`` raises one line."""
        from ...scene.uv_projection import PROJECTIONS, corner_vertices, project_uvs

        if projection == "smart":
            unsupported_method("MeshObject", "add_uv_mapping('smart')", "cube, cylinder and sphere are")()
        if projection not in PROJECTIONS:
            raise InputError(f"Unknown projection: '{projection}'. Please use 'cube', 'cylinder', 'smart' or "
                             "'sphere'.")
        if self.has_uv_mapping() and not overwrite or not self.parts:
            return
        vertices, faces = self.local_mesh()
        corner_uvs = project_uvs(projection, vertices, faces, self.get_local2world_mat())
        start = 0
        for index, part in enumerate(self.parts):
            count = len(part.faces)
            source, uvs, new_faces = corner_vertices(part.faces, corner_uvs[start:start + count])
            start += count
            twin = copy.copy(part)
            twin.forget_derived()
            twin.vertices, twin.faces, twin.uvs = part.vertices[source], new_faces, uvs
            if part.vertex_normals is not None:
                twin.vertex_normals = part.vertex_normals[source]
            if part.vertex_colors is not None:
                twin.vertex_colors = part.vertex_colors[source]
            self.parts[index] = twin

    def join_with_other_objects(self, objects: Sequence["MeshEditing"]) -> None:
        """Blender's join with this object active: every other object's faces move into this object (placed where
        they were in the world), their materials become slots here (a material this object has keeps its slot),
        and the other objects are deleted."""
        inverse = np.linalg.inv(self.get_local2world_mat())
        for obj in objects:
            if obj is self:
                continue
            into_self = inverse @ obj.get_local2world_mat()
            for index, part in enumerate(obj.parts):
                material = obj._slots[min(obj.part_slots[index], len(obj._slots) - 1)] if obj._slots else None
                if material is None:
                    slot = 0
                elif any(material is mine for mine in self._slots):
                    slot = next(i for i, mine in enumerate(self._slots) if mine is material)
                else:
                    self._slots.append(material)
                    slot = len(self._slots) - 1
                self.parts.append(transformed_part(part, into_self))
                self.part_slots.append(slot)
            obj.delete()
