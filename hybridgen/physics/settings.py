"""Settings and result of a physics simulation (:func:`hybridgen.physics.simulate_physics`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..scene.mesh_object import MeshObject
from .shapes import SHAPES, DecompositionSettings


@dataclass(frozen=True)
class PhysicsSettings:
    """Simulation parameters (SI units: s, m, rad, kg, kg/m^3)."""

    min_time: float = 4.0
    """Simulate at least this long (s)."""
    max_time: float = 40.0
    """Stop here even if objects still move (s)."""
    check_interval: float = 1.0
    """Rest check every this many simulated seconds (s)."""
    position_threshold: float = 0.01
    """At rest: the centre of mass moved less than this per interval (m) ..."""
    rotation_threshold: float = 0.1
    """... and turned less than this per interval (rad)."""
    time_step: float = 1.0 / 240.0
    """Bullet's fixed step (s)."""
    substeps: int | None = None
    """Solver substeps per step (Bullet's numSubSteps); None: :func:`~hybridgen.physics.simulate.auto_substeps`."""
    solver_iterations: int = 50
    """Bullet's numSolverIterations."""
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    """World-frame acceleration (m/s^2)."""
    collision_shape: str = "convex_hull"
    """Active objects: convex_hull | convex_decomposition | auto."""
    passive_shape: str = "auto"
    """Passive objects: auto (hull if convex, else triangles) | mesh | convex_hull | convex_decomposition."""
    mass: float | None = None
    """Per active object (kg); None: density x collision volume."""
    density: float = 1000.0
    """Of active objects without a mass (kg/m^3)."""
    friction: float = 0.5
    """Coulomb friction coefficient of every body (Bullet's lateralFriction)."""
    restitution: float = 0.0
    """Bounciness, 0 (none) .. 1 (elastic)."""
    rolling_friction: float = 0.0
    """Resistance to rolling (Bullet's rollingFriction, m)."""
    spinning_friction: float = 0.0
    """Resistance to spinning about the contact normal (Bullet's spinningFriction, m)."""
    linear_damping: float = 0.04
    """Fraction of linear velocity lost per second (Bullet's linearDamping, 1/s)."""
    angular_damping: float = 0.1
    """Fraction of angular velocity lost per second (Bullet's angularDamping, 1/s)."""
    collision_margin: float = 1e-4
    """Bullet inflates every shape by this much (m); bodies rest about twice this apart (module docs)."""
    fall_distance: float = 1.0
    """Below every passive object by this much: fallen, no longer simulated (m)."""
    decomposition: DecompositionSettings = field(default_factory=DecompositionSettings)
    record_interval: float | None = None
    """Record every active object's pose every this many simulated seconds (s; None: only the final poses):
    :attr:`PhysicsResult.trajectory`."""

    def validate(self) -> None:
        """InputError naming the first inconsistent setting."""
        positive = ("max_time", "check_interval", "time_step", "position_threshold", "rotation_threshold",
                    "density", "fall_distance")
        for name in positive:
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)}")
        for name in ("min_time", "friction", "restitution", "rolling_friction", "spinning_friction",
                     "linear_damping", "angular_damping", "collision_margin"):
            if getattr(self, name) < 0:
                raise InputError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.min_time > self.max_time:
            raise InputError(f"min_time {self.min_time} s > max_time {self.max_time} s")
        if self.record_interval is not None and not self.record_interval > 0:
            raise InputError(f"record_interval must be > 0 (or null), got {self.record_interval}")
        if self.mass is not None and not self.mass > 0:
            raise InputError(f"mass must be > 0 (or null for density x volume), got {self.mass}")
        if (self.substeps is not None and self.substeps < 1) or self.solver_iterations < 1:
            raise InputError("substeps (or null for auto) and solver_iterations must be >= 1")
        if self.collision_shape not in SHAPES or self.collision_shape == "mesh":
            raise InputError(f"collision_shape of active objects must be convex_hull, convex_decomposition or "
                             f"auto (Bullet has no dynamic triangle meshes), got {self.collision_shape!r}")
        if self.passive_shape not in SHAPES:
            raise InputError(f"passive_shape must be one of {', '.join(SHAPES)}, got {self.passive_shape!r}")


@dataclass
class PhysicsResult:
    """How the simulation ended. ``moving``: still above the rest thresholds at ``max_time``; ``fallen``:
    dropped below every passive object (their last pose is kept)."""

    simulated_time: float
    steps: int
    at_rest: list[MeshObject]
    moving: list[MeshObject]
    fallen: list[MeshObject]
    wall_seconds: float
    substeps: int = 1
    last_position_change: float = 0.0  # largest per-interval change of the bodies still simulated (m)
    last_rotation_change: float = 0.0  # (rad)
    trajectory: list[list[np.ndarray]] = field(default_factory=list)
    """With ``record_interval``: sample ``k`` (at ``k * record_interval`` s; 0 is the start) holds each active
    object's ``local2world`` in the order they were given (a fallen object keeps its last pose)."""

    def summary(self) -> str:
        text = f"simulated {self.simulated_time:.2f} s, {len(self.at_rest)} objects at rest"
        if self.moving:
            text += f", {len(self.moving)} still moving"
        if self.fallen:
            text += f", {len(self.fallen)} fell off"
        return text
