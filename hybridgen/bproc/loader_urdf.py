"""``bproc.loader.load_urdf``: a URDF robot (:mod:`hybridgen.io.urdf`) as ``bproc.types`` objects at its zero
pose.

As BlenderProc loads it: every ``<visual>`` and ``<collision>`` is a mesh object (a mesh file read as stored,
Z up, or a Blender primitive: a box of the given size, a 32-sided cylinder, a UV sphere) named after the
element or ``<link>_visual`` / ``<link>_collision``, scaled by the element's size as BlenderProc's
``get_size_from_geometry`` scales it (the largest mesh scale; for boxes and cylinders their largest dimension,
on top of the dimensions - BlenderProc's behaviour); a visual's ``<material>`` becomes its only material
(shared by name, white when the URDF gives no color, a ``<texture>`` as base color image). Every link has an
``<link>_inertial`` 3 cm cube at the link's frame (its ``<inertial>``'s origin kept, not applied; without one,
mass 1 kg and unit inertia, urdfpy's default), as BlenderProc makes them. Each link is a :class:`Link` (a mesh
object without geometry) at its zero-pose world matrix; the robot is a :class:`URDFObject` (an entity named after
the robot, BlenderProc's armature) parenting the links and their objects, with BlenderProc's bones for every joint
(:mod:`hybridgen.bproc.urdf_rig`) that move the objects (:mod:`hybridgen.bproc.urdf_object`); collision and
inertial objects are hidden. ``weight_distribution`` changes nothing here (every object follows one bone rigidly,
BlenderProc's default ``rigid``); ``fk_offset`` and ``ik_offset`` place the FK and IK bones (m), which only moves
where BlenderProc's IK controller sits.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..io.urdf import Element, Robot, mesh_file, read_urdf
from ..io.urdf import Inertial as UrdfInertial
from .loader_support import to_mesh_objects
from .types import Material, MeshObject
from .urdf_object import Inertial, Link, URDFObject
from .urdf_rig import build_rig
from .utility import resolve_path

__all__ = ["Inertial", "Link", "URDFObject", "load_urdf"]

INERTIAL_SIZE = 0.03
"""Edge of the cube BlenderProc shows an inertial element as (m)."""


def _bake_scale(obj: MeshObject, scale: np.ndarray) -> None:
    """Scale ``obj``'s mesh by ``scale`` (its pose unchanged), as Blender's apply-scale does."""
    kept = obj.get_scale()
    obj.set_scale(np.asarray(scale) * kept)
    obj.persist_transformation_into_mesh(location=False, rotation=False, scale=True)
    obj.set_scale(kept)


def _size(element: Element) -> float | None:
    """BlenderProc's ``get_size_from_geometry``: the factor it scales a loaded element by."""
    geometry = element.geometry
    if geometry.kind == "box":
        return max(geometry.size)
    if geometry.kind == "cylinder":
        return max(geometry.radius, geometry.length)
    if geometry.kind == "sphere":
        return geometry.radius
    return max(geometry.scale)


def _geometry_object(robot: Robot, element: Element, name: str) -> MeshObject:
    from ..io.mesh_loader import load_objects
    from .object import create_primitive

    geometry = element.geometry
    if geometry.kind == "mesh":
        parts = load_objects(mesh_file(robot, str(geometry.filename)), up_axis="Z")
        obj = to_mesh_objects(parts, skipped=("source_path",))[0]
        obj.persist_transformation_into_mesh()
    elif geometry.kind == "box":
        obj = create_primitive("CUBE")
        _bake_scale(obj, np.asarray(geometry.size) / 2.0)
    elif geometry.kind == "cylinder":
        obj = create_primitive("CYLINDER", radius=geometry.radius, depth=geometry.length)
    else:
        obj = create_primitive("SPHERE", radius=geometry.radius)
    obj.set_name(name)
    return obj


def _element_object(robot: Robot, element: Element, name: str, link_pose: np.ndarray,
                    materials: dict[str, Material]) -> MeshObject:
    obj = _geometry_object(robot, element, element.name or name)
    if element.material is not None:
        wanted = element.material
        material = materials.get(wanted.name)
        if material is None:
            material = Material(wanted.name)
            material.set_principled_shader_value("Base Color", list(wanted.color or (1.0, 1.0, 1.0, 1.0)))
            materials[wanted.name] = material
        if wanted.texture is not None:
            from .bpy_standin import Image

            textured = Material(f"{wanted.name}_texture")
            textured.set_principled_shader_value("Base Color", Image(str(mesh_file(robot, wanted.texture))))
            material = textured
        obj.replace_materials(material)
    size = _size(element)
    if size is not None:
        _bake_scale(obj, np.full(3, size))
    obj.set_local2world_mat(link_pose @ element.origin)
    return obj


def load_urdf(urdf_file: str, weight_distribution: str = "rigid", fk_offset: Any = None,
              ik_offset: Any = None) -> URDFObject:
    """The robot of ``urdf_file`` at its zero pose (module doc)."""
    from .object import create_primitive

    if weight_distribution not in ("envelope", "automatic", "rigid"):
        raise InputError(f"bproc.loader.load_urdf: weight_distribution must be envelope, automatic or rigid, got "
                         f"{weight_distribution!r}")
    robot = read_urdf(resolve_path(urdf_file))
    armature, rigs = build_rig(robot, fk_offset, ik_offset)
    urdf_object = URDFObject(robot.name, [], robot, armature)  # first, as BlenderProc's armature: a link of its
    materials: dict[str, Material] = {}                            # name is then .001
    by_name: dict[str, Link] = {}
    for spec in robot.links:
        pose = robot.link_poses[spec.name]
        visuals = [_element_object(robot, e, f"{spec.name}_visual", pose, materials) for e in spec.visuals]
        collisions = [_element_object(robot, e, f"{spec.name}_collision", pose, materials) for e in spec.collisions]
        element = spec.inertial or UrdfInertial(np.eye(4), 1.0, np.eye(3))  # urdfpy's default, as BlenderProc
        cube = create_primitive("CUBE")
        _bake_scale(cube, np.full(3, INERTIAL_SIZE / 2))
        inertial = Inertial(f"{spec.name}_inertial", cube.parts, element.mass, element.inertia, element.origin)
        inertial.set_local2world_mat(pose)
        cube.delete()
        link = Link(spec.name, pose)
        link.visuals, link.collisions, link.inertial = visuals, collisions, inertial
        link.visual_local2link_mats = [e.origin.copy() for e in spec.visuals]
        link.collision_local2link_mats = [e.origin.copy() for e in spec.collisions]
        link.inertial_local2link_mat = np.eye(4)
        link.armature, link.owner = armature, urdf_object
        joint = robot.joint_of(spec.name)
        if joint is not None:
            link.joint_type, link.joint_name, link.rig = joint.type, joint.name, rigs.get(joint.name)
        if link.rig is not None:
            link.link2bone_mat = np.linalg.inv(pose) @ armature.pose(link.rig.deform.name)
        for obj in [link, *link.get_all_objs()]:
            obj.set_parent(urdf_object)
        by_name[spec.name] = link
    _link_neighbours(robot, by_name)
    urdf_object.links = [by_name[spec.name] for spec in robot.links]
    urdf_object.all_links = list(urdf_object.links)
    urdf_object.hide_links_and_collision_inertial_objs()
    return urdf_object


def _link_neighbours(robot: Robot, links: dict[str, Link]) -> None:
    """Each link's parent and (last) child link, walking the joints from the root as BlenderProc does."""
    children = {joint.child for joint in robot.joints}

    def walk(parent_name: str) -> None:
        for joint in (j for j in robot.joints if j.parent == parent_name):
            links[joint.child].link_parent, links[parent_name].link_child = links[parent_name], links[joint.child]
            walk(joint.child)

    for spec in robot.links:
        if spec.name not in children:
            walk(spec.name)
