"""Blender's rigid-body component of a ``bproc.types.MeshObject`` (BlenderProc's ``enable_rigidbody`` and kin):
what :mod:`hybridgen.bproc.physics` hands to hybridgen's PyBullet simulation.

Values are Blender's: ``mass`` in kg (default: the bound box volume in m^3 times ``mass_factor``, as BlenderProc
computes it), ``collision_margin`` in m, ``friction`` Bullet's Coulomb coefficient, damping the fraction of
velocity lost per second. Collision shapes: ``CONVEX_HULL``, ``MESH`` (passive: Bullet's static triangle mesh;
active: every triangle collides, as Blender's GImpact shape - :mod:`hybridgen.physics.mesh_body`), ``BOX`` (the
object's bound box), and ``COMPOUND`` after :meth:`RigidBodyMixin.build_convex_decomposition_collision_shape` (a
convex decomposition by CoACD, where BlenderProc runs V-HACD: the parts differ, the idea is the same). ``SPHERE``,
``CAPSULE``, ``CYLINDER`` and ``CONE`` are Blender's primitives sized from the object's dimensions, simulated as their
convex hulls (:data:`hybridgen.bproc.physics.PRIMITIVE_SHAPES`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ...errors import InputError

COLLISION_SHAPES = ("BOX", "SPHERE", "CAPSULE", "CYLINDER", "CONE", "CONVEX_HULL", "MESH", "COMPOUND")
MESH_SOURCES = ("BASE", "DEFORM", "FINAL")


@dataclass
class RigidBody:
    """Blender's ``RigidBodyObject`` settings (see the module documentation)."""

    type: str
    collision_shape: str = "CONVEX_HULL"
    collision_margin: float = 0.001
    mesh_source: str = "FINAL"
    mass: float = 1.0
    friction: float = 0.5
    angular_damping: float = 0.1
    linear_damping: float = 0.04
    restitution: float = 0.0
    convex_decomposition: bool = False
    """Set by ``build_convex_decomposition_collision_shape``: the shape is a convex decomposition."""


class RigidBodyMixin:
    """Mixin of :class:`~hybridgen.bproc.types.MeshObject`: needs ``get_bound_box_volume`` and ``get_name``."""

    _rigid_body: RigidBody | None = None
    get_bound_box_volume: Callable[[], float]
    get_name: Callable[[], str]

    def enable_rigidbody(self, active: bool, collision_shape: str = "CONVEX_HULL", collision_margin: float = 0.001,
                         collision_mesh_source: str = "FINAL", mass: float | None = None, mass_factor: float = 1,
                         friction: float = 0.5, angular_damping: float = 0.1, linear_damping: float = 0.04) -> None:
        """Make the object take part in physics: ``active`` objects move, passive ones are fixed obstacles."""
        shape = str(collision_shape).upper()
        if shape not in COLLISION_SHAPES:
            raise InputError(f"enable_rigidbody: collision_shape {collision_shape!r} is not one of "
                             f"{', '.join(COLLISION_SHAPES)}")
        if collision_mesh_source not in MESH_SOURCES:
            raise InputError(f"enable_rigidbody: collision_mesh_source {collision_mesh_source!r} is not one of "
                             f"{', '.join(MESH_SOURCES)}")
        body_mass = self.get_bound_box_volume() * float(mass_factor) if mass is None else float(mass)
        self._rigid_body = RigidBody("ACTIVE" if active else "PASSIVE", shape, float(collision_margin),
                                     collision_mesh_source, body_mass, float(friction), float(angular_damping),
                                     float(linear_damping))

    def build_convex_decomposition_collision_shape(self, vhacd_path: str, temp_dir: str | None = None,
                                                   cache_dir: str = "blenderproc_resources/decomposition_cache") -> None:
        """Collide as a convex decomposition of the mesh (computed by hybridgen's CoACD step, cached in hybridgen's
        cache folder; ``vhacd_path``, ``temp_dir`` and ``cache_dir`` name V-HACD's folders and change nothing)."""
        if self._rigid_body is None:
            self.enable_rigidbody(True, "COMPOUND")
        assert self._rigid_body is not None
        self._rigid_body.convex_decomposition = True

    def disable_rigidbody(self) -> None:
        """Remove the rigid-body component (a warning if there is none, as in BlenderProc)."""
        if self._rigid_body is None:
            import warnings

            warnings.warn(f"MeshObject {self.get_name()} has no rigid_body component enabled")
        self._rigid_body = None

    def has_rigidbody_enabled(self) -> bool:
        return self._rigid_body is not None

    def get_rigidbody(self) -> RigidBody | None:
        """The rigid-body settings (change them in place as Blender's ``rigid_body``), or None."""
        return self._rigid_body
