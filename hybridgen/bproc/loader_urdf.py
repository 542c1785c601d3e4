"""``bproc.loader.load_urdf``: a URDF robot (:mod:`hybridgen.io.urdf`) as ``bproc.types`` objects at its zero
pose.

As BlenderProc loads it: every ``<visual>`` and ``<collision>`` is a mesh object (a mesh file read as stored,
Z up, or a Blender primitive: a box of the given size, a 32-sided cylinder, a UV sphere) named after the
element or ``<link>_visual`` / ``<link>_collision``, scaled by the element's size as BlenderProc's
``get_size_from_geometry`` scales it (the largest mesh scale; for boxes and cylinders their largest dimension,
on top of the dimensions - BlenderProc's behaviour); a visual's ``<material>`` becomes its only material
(shared by name, white when the URDF gives no color, a ``<texture>`` as base color image). Every link has an
``<link>_inertial`` 3 cm cube when it has an ``<inertial>``. Each link is a :class:`Link` entity at its
zero-pose world matrix holding its objects as children; collision and inertial objects are hidden. The robot is
a :class:`URDFObject` (an entity named after the robot) holding the links.

hybridgen has no armature: the joint-space calls (forward and inverse kinematics, bone controllers) raise one
line naming the call; ``get_all_local2world_mats`` gives the links' joint frames (BlenderProc: its bones').
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from ..io.urdf import Element, Robot, mesh_file, read_urdf
from .loader_support import to_mesh_objects
from .types import Material, MeshObject
from .urdf_object import Inertial, Link, URDFObject
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
    """The robot of ``urdf_file`` at its zero pose (module doc). ``weight_distribution``, ``fk_offset`` and
    ``ik_offset`` shape BlenderProc's armature, which hybridgen does not build; they change nothing rendered."""
    from .object import create_primitive

    if weight_distribution not in ("envelope", "automatic", "rigid"):
        raise InputError(f"bproc.loader.load_urdf: weight_distribution must be envelope, automatic or rigid, got "
                         f"{weight_distribution!r}")
    robot = read_urdf(resolve_path(urdf_file))
    urdf_object = URDFObject(robot.name, [], robot)  # first, as BlenderProc's armature: a link of its name is .001
    materials: dict[str, Material] = {}
    links: list[Link] = []
    for spec in robot.links:
        pose = robot.link_poses[spec.name]
        visuals = [_element_object(robot, e, f"{spec.name}_visual", pose, materials) for e in spec.visuals]
        collisions = [_element_object(robot, e, f"{spec.name}_collision", pose, materials) for e in spec.collisions]
        inertial = None
        if spec.inertial is not None:
            cube = create_primitive("CUBE")
            _bake_scale(cube, np.full(3, INERTIAL_SIZE / 2))
            inertial = Inertial(f"{spec.name}_inertial", cube.parts, spec.inertial.mass, spec.inertial.inertia,
                                spec.inertial.origin)
            inertial.set_local2world_mat(pose @ spec.inertial.origin)
            cube.delete()
        link = Link(spec.name, pose)
        link.visuals, link.collisions, link.inertial = visuals, collisions, inertial
        joint = robot.joint_of(spec.name)
        if joint is not None:
            link.joint_type, link.joint_name = joint.type, joint.name
        for obj in link.get_all_objs():
            obj.set_parent(link)
        links.append(link)
    by_name = {spec.name: link for spec, link in zip(robot.links, links)}
    for joint in robot.joints:
        child, parent = by_name.get(joint.child), by_name.get(joint.parent)
        if child is not None and parent is not None:
            child.link_parent, parent.link_child = parent, child
            child.set_parent(parent)
    urdf_object.links = links
    urdf_object.hide_links_and_collision_inertial_objs()
    return urdf_object
