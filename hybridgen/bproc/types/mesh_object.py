"""``bproc.types.MeshObject``: a Blender mesh object over hybridgen :class:`~hybridgen.scene.mesh_object.MeshObject`
parts (BlenderProc's MeshObjectUtility).

A Blender object may hold several materials; a hybridgen mesh holds one, so a mesh object is a list of parts
(``parts``, one per material of the file) whose geometry is in the object's local frame (metres). Material slots
are ``bproc.types.Material`` objects; part ``i`` renders with slot ``min(part_slots[i], slots - 1)`` (its
material index, ``i`` unless faces were split off) as Blender clamps a face's material index, and with Blender's
default grey surface when there is no slot. A mesh whose faces all went to another object has no parts (Blender's
empty mesh: nothing renders, its bound box is the origin). A render poses every part
at the object's ``matrix_world`` of the frame (:meth:`MeshObject.scene_parts`).
"""
from __future__ import annotations

import copy
from typing import Any, Callable, Sequence

import numpy as np

from ...errors import InputError
from ...scene.material import Material as SceneMaterial
from ...scene.mesh_object import MeshObject as ScenePart
from ...scene.shading import shade
from ..session import SESSION
from .entity import Entity, compose, vector3
from .material import Material
from .mesh_editing import MeshEditing, transformed_part
from .mesh_geometry import MeshGeometry
from .modifiers import MeshModifiers
from .rigid_body import RigidBodyMixin
from .unsupported import unsupported_method

BOUND_BOX_CORNERS = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]])
"""Blender's ``bound_box`` corner order: (min/max x, y, z) flags of the 8 corners."""
DEFAULT_SURFACE = SceneMaterial(name="blender_default_surface")
"""What Blender renders a mesh without material with: grey 0.8 Principled, roughness 0.5."""


class MeshObject(Entity, MeshGeometry, MeshEditing, MeshModifiers, RigidBodyMixin):
    """A mesh object; ``parts`` are hybridgen meshes in its local frame, ``_slots`` its material slots. Geometric
    queries (BVH trees, ray casts), mesh edits (UV projection, joining), modifiers (subdivision, displacement,
    solidify) and the rigid body come from the mixins."""

    TYPE = "MESH"

    def __init__(self, name: str, parts: Sequence[ScenePart], slots: Sequence[Material | None] = (),
                 local2world: np.ndarray | None = None) -> None:
        if not parts:
            raise InputError(f"mesh object '{name}' has no geometry")
        super().__init__(name, local2world)
        self.parts: list[ScenePart] = list(parts)
        self.part_slots: list[int] = list(range(len(self.parts)))
        """The material index of each part."""
        self.loose_vertices = np.zeros((0, 3))
        """Vertices of no face (a point cloud's points), local frame, m: they count for the bound box only."""
        self._slots: list[Material | None] = list(slots)
        self.normals_from_file = False
        """Whether the parts' vertex normals are the file's (Blender's custom split normals; set by the loaders)."""
        self.smooth_angle: float | None = None
        """The smallest angle (degrees) of the "Smooth by Angle" modifiers on the object (``add_auto_smooth_modifier``,
        ``set_shading_mode("AUTO")``), None without: smooth faces split at sharper edges, flat faces stay flat."""

    # --- materials ----------------------------------------------------------------------------------------
    def get_materials(self) -> list[Material | None]:
        return list(self._slots)

    def has_materials(self) -> bool:
        return bool(self._slots)

    def set_material(self, index: int, material: Material) -> None:
        if not 0 <= index < len(self._slots):
            raise InputError(f"'{self.get_name()}' has no material slot {index} ({len(self._slots)} slot(s))")
        self._slots[index] = material

    def add_material(self, material: Material) -> None:
        self._slots.append(material)

    def new_material(self, name: str) -> Material:
        """A new default material named ``name``, added as a slot."""
        material = Material(name)
        self.add_material(material)
        return material

    def clear_materials(self) -> None:
        self._slots.clear()

    def replace_materials(self, material: Material) -> None:
        """Every slot goes; ``material`` becomes the only one."""
        self._slots = [material]

    def part_material(self, index: int) -> SceneMaterial:
        """The hybridgen material part ``index`` renders with."""
        if not self._slots:
            return DEFAULT_SURFACE
        number = self.part_slots[index] if index < len(self.part_slots) else index
        slot = self._slots[min(number, len(self._slots) - 1)]
        return DEFAULT_SURFACE if slot is None else slot.blender_obj

    # --- geometry -----------------------------------------------------------------------------------------
    def local_vertices(self) -> np.ndarray:
        """(V, 3) every part's vertices in the local frame, metres."""
        if not self.parts:
            return np.array(self.loose_vertices, dtype=np.float64).reshape(-1, 3)
        return np.concatenate([part.vertices for part in self.parts] + ([self.loose_vertices]
                                                                        if len(self.loose_vertices) else []))

    def get_bound_box(self, local_coords: bool = False) -> np.ndarray:
        """(8, 3) corners of the local axis-aligned box in Blender's order; world coordinates unless
        ``local_coords``."""
        vertices = self.local_vertices()
        if not len(vertices):
            vertices = np.zeros((1, 3))
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        corners = np.where(BOUND_BOX_CORNERS == 1, high, low)
        if local_coords:
            return corners
        matrix = self.get_local2world_mat()
        return corners @ matrix[:3, :3].T + matrix[:3, 3]

    def get_bound_box_volume(self) -> float:
        """Volume of the world-space box spanned by the bound box corners (m^3)."""
        box = self.get_bound_box()
        return float(np.prod(box.max(axis=0) - box.min(axis=0)))

    def _transform_parts(self, matrix: np.ndarray) -> None:
        """Apply a local 4x4 to every part's vertices (and its normals)."""
        self.parts = [transformed_part(part, matrix) for part in self.parts]

    def persist_transformation_into_mesh(self, location: bool = True, rotation: bool = True,
                                         scale: bool = True) -> None:
        """Bake the chosen parts of the pose into the vertices and reset them (the object stays in place)."""
        current = [self._location.value, self._rotation.value, self._scale.value]
        kept = [np.zeros(3) if location else current[0], np.zeros(3) if rotation else current[1],
                np.ones(3) if scale else current[2]]
        self._transform_parts(np.linalg.inv(compose(*kept)) @ compose(*current))
        self._location.set(kept[0])
        self._rotation.set(kept[1])
        self._scale.set(kept[2])

    def get_origin(self) -> np.ndarray:
        """The origin (Blender's ``location``), metres."""
        return self.get_location()

    def set_origin(self, point: Sequence[float] | None = None, mode: str = "POINT") -> np.ndarray:
        """Move the origin to ``point`` (world, ``POINT``), to the area-weighted surface centroid
        (``CENTER_OF_MASS``) or to the centroid of the enclosed volume (``CENTER_OF_VOLUME``) without moving the
        geometry; returns the new origin."""
        basis = self.basis()
        if mode == "POINT":
            if point is None:
                raise InputError("set_origin: mode POINT needs a point")
            world = self.get_local2world_mat()
            local = np.linalg.inv(world) @ np.append(vector3(point, "point"), 1.0)
            target = local[:3]
        elif mode == "CENTER_OF_MASS":
            corners = np.concatenate([part.vertices[part.faces] for part in self.parts])
            areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
            target = (corners.mean(axis=1) * areas[:, None]).sum(axis=0) / max(areas.sum(), 1e-300)
        elif mode == "CENTER_OF_VOLUME":
            target = _volume_centroid(self.parts)
        else:
            raise InputError(f"bproc.types.MeshObject.set_origin: No such mode: {mode}")
        shift = np.eye(4)
        shift[:3, 3] = -target
        self._transform_parts(shift)
        self._location.set(basis[:3, 3] + basis[:3, :3] @ target)
        return self.get_origin()

    def move_origin_to_bottom_mean_point(self) -> None:
        """Move the vertices by minus (world bound box centre x, y, its lowest z), as BlenderProc does (a
        global-axes translation of the mesh; the origin stays)."""
        box = self.get_bound_box()
        delta = -np.array([box.mean(axis=0)[0], box.mean(axis=0)[1], box.min(axis=0)[2]])
        shift = np.eye(4)
        shift[:3, 3] = np.linalg.solve(self.get_local2world_mat()[:3, :3], delta)
        self._transform_parts(shift)

    def clear_custom_splitnormals(self) -> None:
        """Drop the normals read from the file (:attr:`normals_from_file`): the parts that had them shade smooth
        from their faces, as Blender's importers leave such faces smooth (measured with BlenderProc on bpy 4.2: a
        PLY with normals loads smooth, one without flat). Normals hybridgen computed (``set_shading_mode``) stay."""
        if not self.normals_from_file:
            return
        for index, part in enumerate(self.parts):
            if part.vertex_normals is not None:
                self._shade_part(index, "SMOOTH", 30.0)
        self.normals_from_file = False

    def set_shading_mode(self, mode: str, angle_value: float = 30) -> None:
        """Blender's ``FLAT``, ``SMOOTH`` or ``AUTO`` (smooth up to ``angle_value`` degrees: a "Smooth by Angle"
        modifier, which stays, so a later ``SMOOTH`` splits at it too) shading."""
        self.normals_from_file = False
        mode = str(mode).upper()
        if mode == "AUTO":
            self.smooth_angle = _smaller(self.smooth_angle, angle_value)
        if mode in ("SMOOTH", "AUTO") and self.smooth_angle is not None:
            mode, angle_value = "AUTO", self.smooth_angle
        for index in range(len(self.parts)):
            self._shade_part(index, mode, angle_value)

    def add_auto_smooth_modifier(self, angle: float = 30.0) -> None:
        """Blender 4.2's "Smooth by Angle" modifier: smooth faces split at edges sharper than ``angle`` degrees (with
        several modifiers, the smallest angle), flat faces stay flat - measured with BlenderProc on bpy 4.2."""
        self.smooth_angle = _smaller(self.smooth_angle, angle)
        self.normals_from_file = False
        for index, part in enumerate(self.parts):
            if part.vertex_normals is not None:  # smooth faces; flat ones stay flat
                self._shade_part(index, "AUTO", self.smooth_angle)

    def _shade_part(self, index: int, mode: str, angle_value: float) -> None:
        part = self.parts[index]
        try:
            shaded = shade(part.vertices, part.faces, mode, angle_value, part.uvs, part.vertex_colors)
        except ValueError as exc:
            raise InputError(str(exc)) from None
        twin = copy.copy(part)  # parts may be shared with duplicates: replaced, not changed
        twin.vertices, twin.faces, twin.vertex_normals = shaded.vertices, shaded.faces, shaded.vertex_normals
        twin.uvs, twin.vertex_colors = shaded.uvs, shaded.vertex_colors
        self.parts[index] = twin

    def mesh_as_trimesh(self) -> Any:
        """The local-frame mesh (all parts) as a ``trimesh.Trimesh``."""
        import trimesh

        vertices, faces = self.local_mesh()
        return trimesh.Trimesh(vertices.copy(), faces.copy(), process=False)

    def scene_parts(self, frame: int | None) -> list[ScenePart]:
        """The parts as hybridgen meshes posed at ``frame`` with their slot materials (fresh shallow copies:
        a scene assigns them instance ids)."""
        pose = self.world_matrix(frame)
        posed = []
        for index, part in enumerate(self.parts):
            twin = copy.copy(part)
            twin.local2world = pose
            twin.material = self.part_material(index)
            twin.name = self.get_name()
            posed.append(twin)
        return posed

    def _copy_state_from(self, other: Entity) -> None:
        super()._copy_state_from(other)
        assert isinstance(other, MeshObject)
        self.parts = [copy.copy(part) for part in other.parts]
        self.part_slots = list(other.part_slots)
        self._slots = list(other._slots)
        self._rigid_body = copy.copy(other._rigid_body)

    get_mesh: Callable[..., Any] = unsupported_method("MeshObject", "get_mesh", "there is no Blender mesh")
    mesh_as_bmesh: Callable[..., Any] = unsupported_method("MeshObject", "mesh_as_bmesh", "there is no bmesh")
    update_from_bmesh: Callable[..., Any] = unsupported_method("MeshObject", "update_from_bmesh")
    edit_mode: Callable[..., Any] = unsupported_method("MeshObject", "edit_mode")
    object_mode: Callable[..., Any] = unsupported_method("MeshObject", "object_mode")
    add_geometry_nodes: Callable[..., Any] = unsupported_method("MeshObject", "add_geometry_nodes")

    def scale_uv_coordinates(self, factor: float) -> None:
        """Every UV coordinate times ``factor`` (above 1 the texture looks smaller on the object)."""
        if not self.parts or not self.has_uv_mapping():
            raise InputError("Cannot scale UV coordinates of a MeshObject that has no UV mapping.")
        for index, part in enumerate(self.parts):
            twin = copy.copy(part)  # parts may be shared with duplicates: replaced, not changed
            twin.uvs = np.asarray(part.uvs, dtype=np.float64) * float(factor)
            self.parts[index] = twin

    def has_uv_mapping(self) -> bool:
        """Whether every part has texture coordinates."""
        return all(part.uvs is not None for part in self.parts)


def get_all_mesh_objects() -> list[MeshObject]:
    """Every mesh object of the session, in creation order (``bproc.object.get_all_mesh_objects``)."""
    return [e for e in SESSION.entities if isinstance(e, MeshObject)]


def _volume_centroid(parts: list[Any]) -> np.ndarray:
    """Blender's ``ORIGIN_CENTER_OF_VOLUME`` in the local frame: the centroid of the volume the triangles enclose
    (signed tetrahedra from the vertices' mean, for precision), or that mean when they enclose none."""
    vertices = np.concatenate([part.vertices for part in parts]) if parts else np.zeros((1, 3))
    mean = vertices.mean(axis=0)
    corners = np.concatenate([part.vertices[part.faces] for part in parts]) - mean if parts else np.zeros((0, 3, 3))
    volumes = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) / 6.0
    total = volumes.sum()
    if abs(total) <= np.finfo(np.float32).eps:
        return mean
    return mean + (volumes[:, None] * corners.sum(axis=1) / 4.0).sum(axis=0) / total


def _smaller(current: float | None, angle: float) -> float:
    """The effective angle after one more "Smooth by Angle" modifier of ``angle`` degrees."""
    angle = float(angle)
    return angle if current is None else min(current, angle)
