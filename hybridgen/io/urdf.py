"""URDF robot descriptions (ROS's XML format) -> links with their geometry at the zero pose.

Read: ``<link>`` elements with ``<visual>`` / ``<collision>`` (``<origin xyz rpy>``, ``<geometry>`` holding a
``<mesh filename scale>``, ``<box size>``, ``<cylinder radius length>`` or ``<sphere radius>``, a visual's
``<material>`` with ``<color rgba>`` / ``<texture filename>`` or the name of a robot-level material) and
``<inertial>`` (origin, mass); ``<joint>`` elements (name, type, parent, child, origin, axis, limit). ``rpy``
is roll-pitch-yaw about the fixed axes, ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (Blender's XYZ Euler). A link's
zero-pose world matrix is its parent's times the joint origin, from the root link (the one that is no joint's
child). Mesh file names are taken relative to the URDF's folder (absolute ones as they are; ``package://<p>/x``
is looked up as ``x`` relative to a folder named ``<p>`` above the URDF, else to the URDF's folder).
"""
from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..scene.frames import euler_xyz_to_matrix


@dataclass
class Geometry:
    """One geometric element: ``kind`` mesh, box, cylinder or sphere with its values (metres)."""

    kind: str
    filename: str | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    size: tuple[float, float, float] = (1.0, 1.0, 1.0)
    radius: float = 0.0
    length: float = 0.0


@dataclass
class VisualMaterial:
    """A visual's material: its name, RGBA color (None: not given) and texture file (None: none)."""

    name: str
    color: tuple[float, float, float, float] | None = None
    texture: str | None = None


@dataclass
class Element:
    """A ``<visual>`` or ``<collision>``: its origin in the link frame, its geometry and (visuals) material."""

    name: str | None
    origin: np.ndarray
    geometry: Geometry
    material: VisualMaterial | None = None


@dataclass
class Inertial:
    """A link's ``<inertial>``: origin in the link frame, mass (kg) and the 3x3 inertia (kg m^2)."""

    origin: np.ndarray
    mass: float
    inertia: np.ndarray


@dataclass
class Link:
    name: str
    visuals: list[Element] = field(default_factory=list)
    collisions: list[Element] = field(default_factory=list)
    inertial: Inertial | None = None


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    lower: float | None = None
    upper: float | None = None


@dataclass
class Robot:
    """A URDF robot: ``links`` in file order, ``joints``, and each link's zero-pose world matrix."""

    name: str
    path: Path
    links: list[Link]
    joints: list[Joint]
    link_poses: dict[str, np.ndarray]

    def joint_of(self, link_name: str) -> Joint | None:
        """The joint whose child is ``link_name`` (None for the root)."""
        return next((j for j in self.joints if j.child == link_name), None)


def _floats(text: str | None, count: int, default: float, where: str) -> np.ndarray:
    if text is None:
        return np.full(count, default)
    try:
        values = np.array([float(v) for v in text.split()], dtype=np.float64)
    except ValueError:
        raise InputError(f"{where}: {text!r} is not {count} numbers") from None
    if values.size == 1 and count == 3 and where.endswith("scale"):
        values = np.repeat(values, 3)
    if values.size != count or not np.all(np.isfinite(values)):
        raise InputError(f"{where}: {text!r} is not {count} finite numbers")
    return values


def _origin(element: ElementTree.Element | None, where: str) -> np.ndarray:
    pose = np.eye(4)
    if element is None:
        return pose
    pose[:3, :3] = euler_xyz_to_matrix(_floats(element.get("rpy"), 3, 0.0, f"{where} origin rpy"))
    pose[:3, 3] = _floats(element.get("xyz"), 3, 0.0, f"{where} origin xyz")
    return pose


def _geometry(element: ElementTree.Element | None, where: str) -> Geometry:
    if element is None or len(element) == 0:
        raise InputError(f"{where}: no <geometry>")
    shape = element[0]
    if shape.tag == "mesh":
        if not shape.get("filename"):
            raise InputError(f"{where}: <mesh> without filename")
        scale = _floats(shape.get("scale"), 3, 1.0, f"{where} mesh scale")
        return Geometry("mesh", filename=shape.get("filename"), scale=tuple(scale))  # type: ignore[arg-type]
    if shape.tag == "box":
        return Geometry("box", size=tuple(_floats(shape.get("size"), 3, 1.0, f"{where} box size")))  # type: ignore
    if shape.tag == "cylinder":
        return Geometry("cylinder", radius=float(shape.get("radius", 1.0)), length=float(shape.get("length", 1.0)))
    if shape.tag == "sphere":
        return Geometry("sphere", radius=float(shape.get("radius", 1.0)))
    raise InputError(f"{where}: unknown geometry <{shape.tag}> (mesh, box, cylinder or sphere)")


def _material(element: ElementTree.Element | None, named: dict[str, VisualMaterial]) -> VisualMaterial | None:
    if element is None:
        return None
    name = element.get("name", "")
    color = element.find("color")
    texture = element.find("texture")
    if color is None and texture is None and name in named:
        return named[name]
    rgba = None if color is None else tuple(float(v) for v in color.get("rgba", "1 1 1 1").split())
    return VisualMaterial(name, rgba, None if texture is None else texture.get("filename"))  # type: ignore[arg-type]


def read_urdf(path: str | Path) -> Robot:
    """The robot of the URDF file ``path`` (see the module doc)."""
    file = Path(path)
    if not file.is_file():
        raise InputError(f"URDF file not found: '{file}'")
    try:
        root = ElementTree.parse(file).getroot()
    except ElementTree.ParseError as exc:
        raise InputError(f"'{file}' is not valid XML: {exc}") from None
    if root.tag != "robot":
        raise InputError(f"'{file}' is no URDF file (its root element is <{root.tag}>, not <robot>)")
    named = {m.name: m for m in (_material(e, {}) for e in root.findall("material")) if m is not None}
    links = []
    for element in root.findall("link"):
        name = element.get("name", "")
        link = Link(name)
        for tag, into in (("visual", link.visuals), ("collision", link.collisions)):
            for index, sub in enumerate(element.findall(tag)):
                where = f"'{file}' link '{name}' {tag} {index}"
                into.append(Element(sub.get("name"), _origin(sub.find("origin"), where),
                                    _geometry(sub.find("geometry"), where),
                                    _material(sub.find("material"), named) if tag == "visual" else None))
        inertial = element.find("inertial")
        if inertial is not None:
            mass = inertial.find("mass")
            values = inertial.find("inertia")
            matrix = np.zeros((3, 3))
            if values is not None:
                get = {k: float(values.get(k, 0.0)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
                matrix = np.array([[get["ixx"], get["ixy"], get["ixz"]], [get["ixy"], get["iyy"], get["iyz"]],
                                   [get["ixz"], get["iyz"], get["izz"]]])
            link.inertial = Inertial(_origin(inertial.find("origin"), f"'{file}' link '{name}' inertial"),
                                     float(mass.get("value", 0.0)) if mass is not None else 0.0, matrix)
        links.append(link)
    names = {link.name for link in links}
    joints = []
    for element in root.findall("joint"):
        name = element.get("name", "")
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None or parent.get("link") not in names or child.get("link") not in names:
            raise InputError(f"'{file}' joint '{name}': its parent and child must name links of the file")
        axis = element.find("axis")
        limit = element.find("limit")
        joints.append(Joint(name, element.get("type", "fixed"), str(parent.get("link")), str(child.get("link")),
                            _origin(element.find("origin"), f"'{file}' joint '{name}'"),
                            _floats("1 0 0" if axis is None else axis.get("xyz"), 3, 0.0,
                                    f"'{file}' joint '{name}' axis"),
                            None if limit is None or limit.get("lower") is None else float(limit.get("lower", 0)),
                            None if limit is None or limit.get("upper") is None else float(limit.get("upper", 0))))
    if not links:
        raise InputError(f"'{file}' has no <link>")
    poses: dict[str, np.ndarray] = {}
    children = {j.child for j in joints}
    pending = [link.name for link in links if link.name not in children]
    for root_name in pending:
        poses[root_name] = np.eye(4)
    while pending:
        current = pending.pop(0)
        for joint in joints:
            if joint.parent == current and joint.child not in poses:
                poses[joint.child] = poses[current] @ joint.origin
                pending.append(joint.child)
    if len(poses) != len(links):
        raise InputError(f"'{file}': the joints do not form a tree over the links (a loop?)")
    return Robot(root.get("name", file.stem), file, links, joints, poses)


def mesh_file(robot: Robot, filename: str) -> Path:
    """The file a ``<mesh filename>`` of ``robot`` names (see the module doc)."""
    folder = robot.path.parent
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        for ancestor in [folder, *folder.parents]:
            if ancestor.name == package and (ancestor / rest).is_file():
                return ancestor / rest
        candidate = folder / rest
    elif filename.startswith("file://"):
        candidate = Path(filename[len("file://"):])
    else:
        candidate = Path(filename) if os.path.isabs(filename) else folder / filename
    if not candidate.is_file():
        raise InputError(f"URDF '{robot.path}': mesh file not found: '{filename}' (looked for '{candidate}')")
    return candidate
