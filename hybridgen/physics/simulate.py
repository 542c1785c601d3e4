"""Python API: drop active objects onto passive ones with PyBullet (headless DIRECT mode) until they rest.

Frames. PyBullet places a rigid body by its centre of mass and principal axes of inertia. For each active
object, the pose's linear part is split into a rotation and the rest (``local2world[:3,:3] = R @ K``, K
holding scale and any shear); K is baked into the collision vertices, so the simulated body is rigid.
The body frame is then the solid's centre of mass ``c`` with its principal axes ``P`` (both in the
K-scaled object frame): ``body2world = object2world_rigid @ [P | c]``. After the simulation the inverse
gives the object's new origin pose, and ``local2world = [R' | t'] @ K`` keeps the scale.

Contact. Bullet inflates every convex shape and triangle by ``collision_margin``, so bodies come to rest
about ``2 * margin`` apart. Measured on the 20-object tabletop (configs/tabletop_physics.yaml, 12 seeds):
at the default 1e-4 m, objects rest 0.17-0.18 mm above their support and no pair of meshes intersects
(exact edge-vs-triangle test); at margin 0 about 20 pairs overlap by 0.02-0.07 mm, with outliers of
several mm; at 1e-3 m the gap is 2 mm. The exact meshes lie inside their convex hulls; decomposition
parts follow the surface up to CoACD's ``threshold``. Thin objects are kept from passing through
surfaces by substeps (:func:`auto_substeps`); Bullet's swept-sphere CCD had no effect on these multibody
bodies when tried.

Determinism: same scene, settings and PyBullet build give identical poses (``deterministicOverlappingPairs``,
fixed time step, objects created in scene order).
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, SystemSetupError
from ..scene.mesh_object import MeshObject
from .shapes import SHAPES, CollisionGeometry, DecompositionSettings, collision_geometry


def _pybullet() -> Any:
    """PyBullet, imported without the build banner its C extension prints (to the process's stderr)."""
    module = sys.modules.get("pybullet")
    if module is not None:
        return module
    try:
        sys.stderr.flush()
        saved = os.dup(2)
        try:
            with open(os.devnull, "w") as null:
                os.dup2(null.fileno(), 2)
                import pybullet
        finally:
            os.dup2(saved, 2)
            os.close(saved)
    except ImportError:
        raise SystemSetupError("physics needs PyBullet: `.venv/bin/pip install pybullet` "
                               "(or `pip install 'hybridgen[physics]'`)") from None
    return pybullet


@dataclass(frozen=True)
class PhysicsSettings:
    """Simulation parameters (SI units: s, m, rad, kg, kg/m^3)."""

    min_time: float = 4.0  # simulate at least this long
    max_time: float = 40.0  # stop here even if objects still move
    check_interval: float = 1.0  # rest check every this many simulated seconds
    position_threshold: float = 0.01  # at rest: centre of mass moved less than this per interval (m)
    rotation_threshold: float = 0.1  # ... and turned less than this per interval (rad)
    time_step: float = 1.0 / 240.0  # Bullet's fixed step (s)
    substeps: int | None = None  # solver substeps per step (Bullet numSubSteps); None: auto_substeps()
    solver_iterations: int = 50
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    collision_shape: str = "convex_hull"  # active objects: convex_hull | convex_decomposition | auto
    passive_shape: str = "auto"  # passive objects: auto (hull if convex, else triangles) | mesh | convex_hull | ...
    mass: float | None = None  # kg per active object; None: density x collision volume
    density: float = 1000.0
    friction: float = 0.5
    restitution: float = 0.0
    rolling_friction: float = 0.0
    spinning_friction: float = 0.0
    linear_damping: float = 0.04
    angular_damping: float = 0.1
    collision_margin: float = 1e-4
    fall_distance: float = 1.0  # below every passive object by this much: fallen, no longer simulated (m)
    decomposition: DecompositionSettings = field(default_factory=DecompositionSettings)

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

    def summary(self) -> str:
        text = f"simulated {self.simulated_time:.2f} s, {len(self.at_rest)} objects at rest"
        if self.moving:
            text += f", {len(self.moving)} still moving"
        if self.fallen:
            text += f", {len(self.fallen)} fell off"
        return text


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


def _rigid(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, translation
    return out


class _Body:
    """One active object in the simulation and the constant map between its body and object frames."""

    def __init__(self, obj: MeshObject, geometry: CollisionGeometry, rotation: np.ndarray, linear: np.ndarray,
                 mass: float) -> None:
        self.obj = obj
        self.geometry = geometry
        self.linear = linear  # K
        self.mass = mass
        eigenvalues, axes = np.linalg.eigh(geometry.inertia)
        if np.linalg.det(axes) < 0:
            axes[:, 2] *= -1
        self.principal = np.maximum(eigenvalues, 1e-12 * max(eigenvalues.max(), 1e-30)) * mass / geometry.volume
        self.body_in_object = _rigid(axes, geometry.center_mass)  # [P | c]
        object_rigid = _rigid(rotation, obj.local2world[:3, 3])
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


def _write_obj(path: str, parts: Sequence[tuple[np.ndarray, np.ndarray]]) -> None:
    """Parts as separate OBJ objects: PyBullet loads such a file as a compound of one convex hull per part
    (or, with GEOM_FORCE_CONCAVE_TRIMESH, as one triangle mesh)."""
    lines: list[str] = []
    offset = 1
    for index, (vertices, faces) in enumerate(parts):
        lines.append(f"o part{index}")
        lines.extend(f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in vertices)
        lines.extend(f"f {a + offset} {b + offset} {c + offset}" for a, b, c in faces)
        offset += len(vertices)
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")


class _World:
    """A PyBullet DIRECT client holding the bodies of one simulation."""

    def __init__(self, settings: PhysicsSettings, workdir: str, substeps: int) -> None:
        self.pb = _pybullet()
        self.settings = settings
        self.workdir = workdir
        self.client = self.pb.connect(self.pb.DIRECT)
        self.files = 0
        self.pb.resetSimulation(physicsClientId=self.client)
        self.pb.setPhysicsEngineParameter(fixedTimeStep=settings.time_step, numSubSteps=substeps,
                                          numSolverIterations=settings.solver_iterations,
                                          deterministicOverlappingPairs=1, physicsClientId=self.client)
        self.pb.setGravity(*settings.gravity, physicsClientId=self.client)

    def close(self) -> None:
        self.pb.disconnect(physicsClientId=self.client)

    def _file(self, parts: Sequence[tuple[np.ndarray, np.ndarray]]) -> str:
        self.files += 1
        path = os.path.join(self.workdir, f"shape{self.files}.obj")
        _write_obj(path, parts)
        return path

    def shape(self, geometry: CollisionGeometry, parts: list[tuple[np.ndarray, np.ndarray]]) -> int:
        """A collision shape: a static triangle mesh, one convex hull, or a compound of convex hulls."""
        pb, cid = self.pb, self.client
        try:
            if geometry.kind == "mesh":
                vertices, faces = parts[0]
                if len(vertices) <= 100_000:
                    return pb.createCollisionShape(pb.GEOM_MESH, vertices=vertices.tolist(),
                                                   indices=faces.ravel().tolist(),
                                                   flags=pb.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=cid)
                # PyBullet's in-memory mesh is limited in size; a file has no such limit
                return pb.createCollisionShape(pb.GEOM_MESH, fileName=self._file(parts),
                                               flags=pb.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=cid)
            if len(parts) == 1:
                return pb.createCollisionShape(pb.GEOM_MESH, vertices=parts[0][0].tolist(), physicsClientId=cid)
            return pb.createCollisionShape(pb.GEOM_MESH, fileName=self._file(parts), physicsClientId=cid)
        except pb.error as exc:
            raise InputError(f"PyBullet could not build its collision shape: {exc}") from None

    def add_static(self, obj: MeshObject) -> int:
        s = self.settings
        kind = shape_of(obj, s.passive_shape, active=False)
        try:
            geometry = collision_geometry(obj.vertices, obj.faces, kind, obj.local2world[:3, :3], s.decomposition,
                                          active=False)
        except InputError as exc:
            raise InputError(f"passive object '{obj.name}': {exc}") from None
        shape = self.shape(geometry, geometry.parts)
        body = self.pb.createMultiBody(0.0, shape, basePosition=obj.local2world[:3, 3].tolist(),
                                       physicsClientId=self.client)
        self._dynamics(body)
        return body

    def add_active(self, body: _Body) -> None:
        from scipy.spatial.transform import Rotation

        shape = self.shape(body.geometry, body.body_parts())
        quaternion = Rotation.from_matrix(body.start[:3, :3]).as_quat()  # x, y, z, w as PyBullet
        body.id = self.pb.createMultiBody(body.mass, shape, basePosition=body.start[:3, 3].tolist(),
                                          baseOrientation=quaternion.tolist(),
                                          physicsClientId=self.client)
        self._dynamics(body.id, mass=body.mass, localInertiaDiagonal=body.principal.tolist())

    def _dynamics(self, body: int, **extra: Any) -> None:
        s = self.settings
        self.pb.changeDynamics(body, -1, lateralFriction=s.friction, restitution=s.restitution,
                               rollingFriction=s.rolling_friction, spinningFriction=s.spinning_friction,
                               linearDamping=s.linear_damping, angularDamping=s.angular_damping,
                               collisionMargin=s.collision_margin, physicsClientId=self.client, **extra)

    def pose(self, body: int) -> np.ndarray:
        from scipy.spatial.transform import Rotation

        position, quaternion = self.pb.getBasePositionAndOrientation(body, physicsClientId=self.client)
        return _rigid(Rotation.from_quat(quaternion).as_matrix(), np.asarray(position))


def _rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    cosine = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))


SHAPE_ATTRIBUTE = "collision_shape"
"""An object attribute that overrides the collision shape kind for that object (e.g. for one concave mesh)."""


def shape_of(obj: MeshObject, default: str, active: bool) -> str:
    """The collision shape kind of ``obj``: its ``collision_shape`` attribute, else ``default``."""
    kind = obj.attributes.get(SHAPE_ATTRIBUTE, default)
    allowed = [k for k in SHAPES if k != "mesh" or not active]
    if kind not in allowed:
        role = "active" if active else "passive"
        raise InputError(f"{role} object '{obj.name}': collision_shape {kind!r} is not one of {', '.join(allowed)}"
                         + (" (Bullet has no moving triangle meshes)" if kind == "mesh" else ""))
    return str(kind)


def active_body(obj: MeshObject, settings: PhysicsSettings) -> _Body:
    """The simulated body of an active object (its collision geometry, mass and inertia)."""
    rotation, linear = split_linear(obj.local2world[:3, :3])
    kind = shape_of(obj, settings.collision_shape, active=True)
    try:
        geometry = collision_geometry(obj.vertices, obj.faces, kind, linear, settings.decomposition)
    except InputError as exc:
        raise InputError(f"active object '{obj.name}': {exc}") from None
    mass = settings.mass if settings.mass is not None else settings.density * geometry.volume
    return _Body(obj, geometry, rotation, linear, mass)


MAX_AUTO_SUBSTEPS = 16


def auto_substeps(bodies: Sequence[_Body], passive: Sequence[MeshObject], settings: PhysicsSettings) -> int:
    """Substeps so that no body moves more than 40 % of its thickness per substep at the speed of a free fall
    from its start down to the lowest passive object (at most 16): thin objects then cannot pass through a
    surface between two contact checks (Bullet's swept-sphere CCD did not prevent that for these bodies).
    """
    lowest = min(float(o.world_vertices()[:, 2].min()) for o in passive)
    gravity = float(np.linalg.norm(settings.gravity))
    needed = 1
    for body in bodies:
        height = max(0.0, float(body.start[2, 3]) - lowest)
        speed = np.sqrt(2.0 * gravity * height)
        needed = max(needed, int(np.ceil(speed * settings.time_step / (0.4 * body.thickness()))))
    return int(min(needed, MAX_AUTO_SUBSTEPS))


def simulate_physics(active: Sequence[MeshObject], passive: Sequence[MeshObject],
                     settings: PhysicsSettings | None = None) -> PhysicsResult:
    """Let ``active`` objects fall (gravity) onto ``passive`` ones, which do not move, for at least
    ``min_time`` and until every active object moved less than the rest thresholds during one
    ``check_interval`` (or ``max_time``). Writes the final poses into the active objects' ``local2world``
    (keeping their scale) and returns how the simulation ended."""
    settings = settings or PhysicsSettings()
    settings.validate()
    if not active:
        raise InputError("no active object to simulate")
    if not passive:
        raise InputError("no passive object for the active ones to fall onto")
    overlap = [o.name for o in active if any(o is p for p in passive)]
    if overlap:
        raise InputError(f"object(s) both active and passive: {', '.join(overlap)}")
    start = time.perf_counter()
    bodies = [active_body(obj, settings) for obj in active]
    floor = min(float(o.world_vertices()[:, 2].min()) for o in passive) - settings.fall_distance
    substeps = settings.substeps or auto_substeps(bodies, passive, settings)
    with tempfile.TemporaryDirectory(prefix="hybridgen-physics-") as workdir:
        world = _World(settings, workdir, substeps)
        try:
            for obj in passive:
                world.add_static(obj)
            for body in bodies:
                world.add_active(body)
            result = _run(world, bodies, settings, floor)
        finally:
            world.close()
    result.wall_seconds = time.perf_counter() - start
    result.substeps = substeps
    return result


def _run(world: _World, bodies: list[_Body], settings: PhysicsSettings, floor: float) -> PhysicsResult:
    steps_per_check = max(1, round(settings.check_interval / settings.time_step))
    max_steps = max(1, round(settings.max_time / settings.time_step))
    poses = {id(b): world.pose(b.id) for b in bodies}
    final: dict[int, np.ndarray] = {}
    fallen: list[_Body] = []
    live = list(bodies)
    moving: list[_Body] = live
    steps = 0
    position_change = rotation_change = 0.0
    while steps < max_steps and live:
        for _ in range(min(steps_per_check, max_steps - steps)):
            world.pb.stepSimulation(physicsClientId=world.client)
        steps += min(steps_per_check, max_steps - steps)
        now = {id(b): world.pose(b.id) for b in live}
        for body in list(live):
            if now[id(body)][2, 3] < floor:
                fallen.append(body)
                live.remove(body)
                final[id(body)] = now[id(body)]
                world.pb.removeBody(body.id, physicsClientId=world.client)
        shifts = {id(b): float(np.linalg.norm(now[id(b)][:3, 3] - poses[id(b)][:3, 3])) for b in live}
        turns = {id(b): _rotation_angle(now[id(b)], poses[id(b)]) for b in live}
        moving = [b for b in live if shifts[id(b)] >= settings.position_threshold
                  or turns[id(b)] >= settings.rotation_threshold]
        position_change = max(shifts.values(), default=0.0)
        rotation_change = max(turns.values(), default=0.0)
        poses.update(now)
        if steps * settings.time_step >= settings.min_time - 1e-9 and not moving:
            break
    for body in live:
        final[id(body)] = poses[id(body)]
    for body in bodies:
        body.obj.local2world = body.local2world(final[id(body)])
    moving_ids = {id(b) for b in moving} if live else set()
    fallen_ids = {id(b) for b in fallen}
    return PhysicsResult(
        simulated_time=steps * settings.time_step, steps=steps,
        at_rest=[b.obj for b in bodies if id(b) not in moving_ids and id(b) not in fallen_ids],
        moving=[b.obj for b in bodies if id(b) in moving_ids and id(b) not in fallen_ids],
        fallen=[b.obj for b in fallen], wall_seconds=0.0,
        last_position_change=position_change, last_rotation_change=rotation_change)
