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

import tempfile
import time
from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import InputError
from ..scene.mesh_object import MeshObject
from .bodies import Body, active_body
from .bullet_world import BulletWorld
from .settings import PhysicsResult, PhysicsSettings

def _rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    cosine = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))


MAX_AUTO_SUBSTEPS = 16


def auto_substeps(bodies: Sequence[Body], passive: Sequence[MeshObject], settings: PhysicsSettings) -> int:
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
                     settings: PhysicsSettings | None = None,
                     per_object: Mapping[int, PhysicsSettings] | None = None) -> PhysicsResult:
    """Let ``active`` objects fall (gravity) onto ``passive`` ones, which do not move, for at least
    ``min_time`` and until every active object moved less than the rest thresholds during one
    ``check_interval`` (or ``max_time``). Writes the final poses into the active objects' ``local2world``
    (keeping their scale) and returns how the simulation ended. ``per_object`` (keyed by ``id(obj)``) gives an
    object its own body settings (shape, mass, density, friction, restitution, damping, margin, decomposition);
    the world's (time, gravity, solver) are ``settings``'."""
    settings = settings or PhysicsSettings()
    own = dict(per_object or {})
    settings.validate()
    if not active:
        raise InputError("no active object to simulate")
    if not passive:
        raise InputError("no passive object for the active ones to fall onto")
    overlap = [o.name for o in active if any(o is p for p in passive)]
    if overlap:
        raise InputError(f"object(s) both active and passive: {', '.join(overlap)}")
    start = time.perf_counter()
    bodies = [active_body(obj, own.get(id(obj), settings)) for obj in active]
    floor = min(float(o.world_vertices()[:, 2].min()) for o in passive) - settings.fall_distance
    substeps = settings.substeps or auto_substeps(bodies, passive, settings)
    with tempfile.TemporaryDirectory(prefix="hybridgen-physics-") as workdir:
        world = BulletWorld(settings, workdir, substeps)
        try:
            for obj in passive:
                world.add_static(obj, own.get(id(obj), settings))
            for body in bodies:
                world.add_active(body)
            result = _run(world, bodies, settings, floor)
        finally:
            world.close()
    result.wall_seconds = time.perf_counter() - start
    result.substeps = substeps
    return result


def _run(world: BulletWorld, bodies: list[Body], settings: PhysicsSettings, floor: float) -> PhysicsResult:
    steps_per_check = max(1, round(settings.check_interval / settings.time_step))
    max_steps = max(1, round(settings.max_time / settings.time_step))
    poses = {id(b): world.pose(b.id) for b in bodies}
    final: dict[int, np.ndarray] = {}
    fallen: list[Body] = []
    live = list(bodies)
    moving: list[Body] = live
    steps = 0
    position_change = rotation_change = 0.0
    record = max(1, round(settings.record_interval / settings.time_step)) if settings.record_interval else 0
    trajectory = [[b.local2world(poses[id(b)]) for b in bodies]] if record else []
    while steps < max_steps and live:
        for _ in range(min(steps_per_check, max_steps - steps)):
            world.pb.stepSimulation(physicsClientId=world.client)
            steps += 1
            if record and steps % record == 0:
                trajectory.append([b.local2world(world.pose(b.id) if b in live else final[id(b)]) for b in bodies])
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
        last_position_change=position_change, last_rotation_change=rotation_change, trajectory=trajectory)
