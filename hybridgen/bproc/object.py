"""``bproc.object``: the scene's mesh objects, primitives, empties and points of interest (BlenderProc's
MeshObjectUtility / EntityUtility).

``create_primitive`` makes Blender's primitives with Blender's default sizes (``CUBE``/``PLANE`` ``size`` 2 m,
``SPHERE`` ``radius`` 1 m, ``CYLINDER``/``CONE`` ``radius`` 1 m and ``depth`` 2 m), flat-shaded and without a
material slot, as ``bpy.ops.mesh.primitive_*_add`` does; the plane has Blender's UV map (0..1 along x and y), the
others none. The sphere is hybridgen's icosphere where Blender's is a UV sphere (same radius, different facets)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..scene.primitives import make_primitive
from .bvh_tree import create_bvh_tree_multi_objects, scene_ray_cast
from .face_slicer import extract_floor, slice_faces_with_normals
from .object_replacer import replace_objects
from .physics import simulate_physics, simulate_physics_and_fix_final_poses
from .placement import sample_poses, sample_poses_on_surface
from .types import Entity, MeshObject
from .types.mesh_object import get_all_mesh_objects
from .types.unsupported import fail, module_getattr

__all__ = ["compute_poi", "convert_to_entities", "convert_to_meshes", "create_bvh_tree_multi_objects", "create_empty",
           "create_from_point_cloud", "create_primitive", "create_with_empty_mesh", "delete_multiple",
           "disable_all_rigid_bodies", "extract_floor", "get_all_mesh_objects", "merge_objects", "replace_objects", "sample_poses",
           "sample_poses_on_surface", "scene_ray_cast", "simulate_physics", "simulate_physics_and_fix_final_poses",
           "slice_faces_with_normals"]

SHAPES = {"CUBE": ("cube", "Cube"), "PLANE": ("plane", "Plane"), "SPHERE": ("sphere", "Sphere"),
          "CYLINDER": ("cylinder", "Cylinder"), "CONE": ("cone", "Cone")}
"""BlenderProc shape -> (hybridgen primitive, Blender's object name)."""
POSE_KEYS = ("location", "rotation", "scale")


def create_primitive(shape: str, **kwargs: Any) -> MeshObject:
    """A new primitive mesh object (see the module documentation); ``location``, ``rotation`` (XYZ Euler, rad)
    and ``scale`` set its pose."""
    upper = str(shape).upper()
    if upper not in SHAPES:
        fail(f"bproc.object.create_primitive({shape!r})", f"shapes: {', '.join(SHAPES)}")
    unknown = set(kwargs) - {"size", "radius", "depth", *POSE_KEYS}
    if unknown:
        fail(f"bproc.object.create_primitive({upper}, {', '.join(sorted(unknown))}=...)")
    kind, name = SHAPES[upper]
    if kind in ("cube", "plane"):
        size = float(kwargs.get("size", 2.0))
        part = make_primitive(kind, size)
        if kind == "plane":  # Blender's UV map of its plane: (x / size + 0.5, y / size + 0.5)
            part.uvs = part.vertices[:, :2] / size + 0.5
    else:
        radius = float(kwargs.get("radius", 1.0))
        part = make_primitive(kind, 2 * radius)
        if kind != "sphere" and "depth" in kwargs:
            part.vertices = part.vertices * np.array([1.0, 1.0, float(kwargs["depth"]) / (2 * radius)])
    part.vertex_normals = None  # Blender's primitives are flat-shaded
    part.__dict__.pop("face_normals", None)
    obj = MeshObject(name, [part])
    if "location" in kwargs:
        obj.set_location(kwargs["location"])
    if "rotation" in kwargs:
        obj.set_rotation_euler(kwargs["rotation"])
    if "scale" in kwargs:
        obj.set_scale(kwargs["scale"])
    return obj


def convert_to_meshes(blender_objects: Sequence[Any]) -> list[MeshObject]:
    """The mesh objects among ``blender_objects`` (they already are hybridgen's)."""
    return [obj for obj in blender_objects if isinstance(obj, MeshObject)]


def convert_to_entities(blender_objects: Sequence[Any], convert_to_subclasses: bool = False) -> list[Entity]:
    return [obj for obj in blender_objects if isinstance(obj, Entity)]


def create_empty(entity_name: str, empty_type: str = "plain_axes") -> Entity:
    """An empty: a named pose without geometry (e.g. a focus point)."""
    return Entity(entity_name)


def delete_multiple(entities: Sequence[Entity], remove_all_offspring: bool = False) -> None:
    for entity in entities:
        if entity.is_valid():
            entity.delete(remove_all_offspring)


def merge_objects(objects: Sequence[Entity], merged_object_name: str = "merged_object") -> Entity:
    """A new empty named ``merged_object_name`` becomes the parent of every object of ``objects`` that has no
    parent yet (each keeps its world pose); returns the empty."""
    if merged_object_name == "":
        raise InputError("merge_objects: the parent object name cannot be empty")
    parent = create_empty(merged_object_name)
    for obj in objects:
        if obj.get_parent() is None:
            obj.set_parent(parent)
    return parent


def disable_all_rigid_bodies() -> None:
    """Remove the rigid-body component of every mesh object that has one."""
    for obj in get_all_mesh_objects():
        if obj.has_rigidbody_enabled():
            obj.disable_rigidbody()


def compute_poi(objects: Sequence[MeshObject]) -> np.ndarray:
    """BlenderProc's point of interest (world, m): of the objects' world bound box centres, the one closest to
    their mean. ``objects`` may be any sequence (a list, a numpy array of objects)."""
    if len(objects) == 0:
        raise InputError("compute_poi needs at least one object")
    centres = np.array([obj.get_bound_box().mean(axis=0) for obj in objects])
    return centres[np.argmin(np.linalg.norm(centres - centres.mean(axis=0), axis=1))]


POINT_SPHERE_RADIUS = 0.015
"""Radius (m) of the icosphere BlenderProc's point-cloud visualization puts on every point."""


def create_with_empty_mesh(object_name: str, mesh_name: str | None = None) -> MeshObject:
    """A new mesh object without geometry (it renders nothing; its bound box is the origin)."""
    obj = MeshObject(object_name, [make_primitive("cube", 1.0)])
    obj.parts, obj.part_slots = [], []
    return obj


def create_from_point_cloud(points: Any, object_name: str, add_geometry_nodes_visualization: bool = False) \
        -> MeshObject:
    """A mesh object whose vertices are the (N, 3) world ``points`` (rows with a NaN left out; they render
    nothing). With ``add_geometry_nodes_visualization`` every point carries an icosahedron of radius 1.5 cm
    (Blender's default icosphere node) with a new red material ``point_cloud_mat``, as BlenderProc's geometry
    nodes draw them (:mod:`hybridgen.scene.point_instances`)."""
    from ..scene.mesh_object import MeshObject as ScenePart
    from ..scene.point_instances import instanced
    from ..scene.primitive_meshes import icosphere

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    points = points[~np.isnan(points).any(axis=1)]
    obj = create_with_empty_mesh(object_name)
    obj.loose_vertices = points
    if add_geometry_nodes_visualization and len(points):
        vertices, faces = instanced(points, *icosphere(0, POINT_SPHERE_RADIUS))
        obj.parts, obj.part_slots = [ScenePart(obj.get_name(), vertices, faces)], [0]
        material = obj.new_material("point_cloud_mat")
        material.set_principled_shader_value("Base Color", [1, 0, 0, 1])
    return obj


__getattr__ = module_getattr("object", ["create_from_blender_mesh"])
