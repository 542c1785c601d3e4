"""Active objects as rigid bodies: the pose split into rotation and scale, the collision geometry, mass and
principal inertia, and the constant map between body frame (centre of mass, principal axes) and object
frame (see :mod:`hybridgen.physics.simulate` for the frames)."""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..scene.frames import make_pose
from ..scene.mesh_object import MeshObject
from .mesh_body import triangle_geometry
from .settings import PhysicsSettings
from .shapes import SHAPES, CollisionGeometry, collision_geometry


def split_linear(linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``linear = R @ K`` with R a proper rotation (polar decomposition) and K the scale/shear/mirror rest."""
    from scipy.linalg import polar

    linear = np.asarray(linear, dtype=np.float64)
    if abs(np.linalg.det(linear)) < 1e-18:
        raise InputError("its pose has a zero scale")
    rotation, _ = polar(linear)
    if np.linalg.det(rotation) < 0:  # a mirrored pose: keep R proper, the mirror goes into K
        rotation = rotation @ np.diag([1.0, 1.0, -1.0])
    return rotation, rotation.T @ linear


class Body:
    """One active object in the simulation and the constant map between its body and object frames."""

    def __init__(self, obj: MeshObject, geometry: CollisionGeometry, rotation: np.ndarray, linear: np.ndarray,
                 mass: float, settings: PhysicsSettings | None = None) -> None:
        self.obj = obj
        self.settings = settings or PhysicsSettings()
        """This body's settings (friction, damping, margin, mass: the simulation's or its own)."""
        self.geometry = geometry
        self.linear = linear  # K
        self.mass = mass
        eigenvalues, axes = np.linalg.eigh(geometry.inertia)
        if np.linalg.det(axes) < 0:
            axes[:, 2] *= -1
        self.principal = np.maximum(eigenvalues, 1e-12 * max(eigenvalues.max(), 1e-30)) * mass / geometry.volume
        self.body_in_object = make_pose(axes, geometry.center_mass)  # [P | c]
        object_rigid = make_pose(rotation, obj.local2world[:3, 3])
        self.start = object_rigid @ self.body_in_object
        self.id = -1

    def thickness(self) -> float:
        """The smallest extent of the collision geometry along its principal axes (m)."""
        points = np.concatenate([v for v, _ in self.body_parts()])
        return float(np.ptp(points, axis=0).min())

    def body_parts(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Convex parts in the body frame (centre of mass, principal axes)."""
        axes, centre = self.body_in_object[:3, :3], self.body_in_object[:3, 3]
        return [((v - centre) @ axes, f) for v, f in self.geometry.parts]

    def local2world(self, body2world: np.ndarray) -> np.ndarray:
        """The object's pose for a body pose: rigid part from the body, scale K kept."""
        object_rigid = body2world @ np.linalg.inv(self.body_in_object)
        out = object_rigid.copy()
        out[:3, :3] = object_rigid[:3, :3] @ self.linear
        return out


SHAPE_ATTRIBUTE = "collision_shape"
"""An object attribute that overrides the collision shape kind for that object (e.g. for one concave mesh)."""


def shape_of(obj: MeshObject, default: str, active: bool) -> str:
    """The collision shape kind of ``obj``: its ``collision_shape`` attribute, else ``default``. ``mesh`` for an
    active object is its triangles as a compound (:mod:`hybridgen.physics.mesh_body`)."""
    kind = obj.attributes.get(SHAPE_ATTRIBUTE, default)
    if kind not in SHAPES:
        role = "active" if active else "passive"
        raise InputError(f"{role} object '{obj.name}': collision_shape {kind!r} is not one of {', '.join(SHAPES)}")
    return str(kind)


def active_body(obj: MeshObject, settings: PhysicsSettings) -> Body:
    """The simulated body of an active object (its collision geometry, mass and inertia)."""
    rotation, linear = split_linear(obj.local2world[:3, :3])
    kind = shape_of(obj, settings.collision_shape, active=True)
    try:
        if kind == "mesh":
            geometry = triangle_geometry(obj.vertices, obj.faces, linear, needs_volume=settings.mass is None)
        else:
            geometry = collision_geometry(obj.vertices, obj.faces, kind, linear, settings.decomposition)
    except InputError as exc:
        raise InputError(f"active object '{obj.name}': {exc}") from None
    mass = settings.mass if settings.mass is not None else settings.density * geometry.volume
    return Body(obj, geometry, rotation, linear, mass, settings)
