"""``bproc.object``: the scene's mesh objects, primitives, empties and points of interest (BlenderProc's
MeshObjectUtility / EntityUtility).

``create_primitive`` makes Blender 4.2's primitives as ``bpy.ops.mesh.primitive_*_add`` does (BlenderProc passes
its keyword arguments on): the same vertices, polygons (corner order included) and UV map
(:mod:`hybridgen.scene.blender_primitives`, measured with bpy 4.2), flat-shaded, without a material slot, with
Blender's arguments and defaults - ``CUBE``/``PLANE`` ``size`` 2 m, ``SPHERE`` (a UV sphere) ``radius`` 1 m,
``segments`` 32, ``ring_count`` 16, ``CYLINDER`` ``radius`` 1 m, ``CONE`` ``radius1`` 1 m and ``radius2`` 0,
both ``depth`` 2 m, ``vertices`` 32, ``end_fill_type`` NGON; ``calc_uvs`` False leaves the mesh without UVs. As
in Blender, ``scale`` is baked into the mesh (the object's scale stays 1) but for ``PLANE``, whose object
BlenderProc scales; ``location`` and ``rotation`` (XYZ Euler, rad) pose the object. The polygons are kept for
modifiers (subdivision reads Blender's quads). ``MONKEY`` (Suzanne) stops with one line: its mesh is Blender's
own data table, not reproduced here."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..scene.primitives import make_primitive
from .bvh_tree import create_bvh_tree_multi_objects, scene_ray_cast
from .face_slicer import extract_floor, slice_faces_with_normals
from .object_replacer import replace_objects
from .placement import sample_poses, sample_poses_on_surface
from .types import Entity, MeshObject
from .types.mesh_object import get_all_mesh_objects
from .types.unsupported import fail, module_getattr

__all__ = ["compute_poi", "convert_to_entities", "convert_to_meshes", "create_bvh_tree_multi_objects", "create_empty",
           "create_from_point_cloud", "create_primitive", "create_with_empty_mesh", "delete_multiple",
           "disable_all_rigid_bodies", "extract_floor", "get_all_mesh_objects", "merge_objects", "replace_objects", "sample_poses",
           "sample_poses_on_surface", "scene_ray_cast", "simulate_physics", "simulate_physics_and_fix_final_poses",
           "slice_faces_with_normals"]

SHAPES = {"CUBE": ("cube", "Cube", ("size",)), "PLANE": ("plane", "Plane", ("size",)),
          "SPHERE": ("uv_sphere", "Sphere", ("radius", "segments", "ring_count")),
          "CYLINDER": ("cylinder", "Cylinder", ("radius", "depth", "vertices", "end_fill_type")),
          "CONE": ("cone", "Cone", ("radius1", "radius2", "depth", "vertices", "end_fill_type"))}
"""BlenderProc shape -> (:mod:`hybridgen.scene.blender_primitives` builder, Blender's object name, the builder's
arguments)."""
POSE_KEYS = ("location", "rotation", "scale")
IGNORED_KEYS = ("calc_uvs", "enter_editmode", "align")


def create_primitive(shape: str, **kwargs: Any) -> MeshObject:
    """A new primitive mesh object (see the module documentation)."""
    from ..scene import blender_primitives
    from ..scene.material import Material as SceneMaterial
    from ..scene.mesh_object import MeshObject as ScenePart

    upper = str(shape).upper()
    if upper == "MONKEY":
        fail("bproc.object.create_primitive('MONKEY')", "Suzanne's mesh is Blender's own data table")
    if upper not in SHAPES:
        fail(f"bproc.object.create_primitive({shape!r})", f"shapes: {', '.join(SHAPES)}")
    kind, name, arguments = SHAPES[upper]
    unknown = set(kwargs) - {*arguments, *POSE_KEYS, *IGNORED_KEYS}
    if unknown:
        fail(f"bproc.object.create_primitive({upper}, {', '.join(sorted(unknown))}=...)",
             f"Blender's primitive_{kind}_add takes {', '.join(arguments)}")
    if kwargs.get("align", "WORLD") != "WORLD":
        fail(f"bproc.object.create_primitive({upper}, align={kwargs['align']!r})", "align='WORLD' only")
    mesh = getattr(blender_primitives, kind)(**{key: kwargs[key] for key in arguments if key in kwargs})
    if "scale" in kwargs and upper != "PLANE":  # Blender bakes the operator's scale into the mesh
        mesh.positions = mesh.positions * np.asarray(kwargs["scale"], dtype=np.float64).reshape(3)
    if not kwargs.get("calc_uvs", True):
        mesh.attributes.pop("uvs")
    template = ScenePart(name=name, vertices=mesh.positions, faces=[[0, 1, 2]], material=SceneMaterial(
        name=f"{kind}_material"), uvs=np.zeros((len(mesh.positions), 2)) if "uvs" in mesh.attributes else None)
    obj = MeshObject(name, [template])
    obj._set_stack_mesh(mesh)  # Blender's polygons and UVs, kept for modifiers
    if "location" in kwargs:
        obj.set_location(kwargs["location"])
    if "rotation" in kwargs:
        obj.set_rotation_euler(kwargs["rotation"])
    if "scale" in kwargs and upper == "PLANE":  # Blender ignores it for planes; BlenderProc sets the object's
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


# the physics stack (~20 ms of imports) is imported when a script first simulates
__getattr__ = module_getattr("object", ["create_from_blender_mesh"],
                             lazy={"simulate_physics": "physics", "simulate_physics_and_fix_final_poses": "physics"},
                             namespace=globals())
