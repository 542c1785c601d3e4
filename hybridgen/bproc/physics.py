"""``bproc.object.simulate_physics_and_fix_final_poses`` and ``simulate_physics`` (BlenderProc's PhysicsSimulation)
over :func:`hybridgen.physics.simulate_physics` (PyBullet, the ``physics`` extra: one line when it is missing).

Every mesh object with a rigid body (:mod:`hybridgen.bproc.types.rigid_body`) takes part: active ones fall under
gravity (world -Z, 9.81 m/s^2) onto the passive ones with their own mass, friction, damping and collision margin.
Blender's clock: 24 frames per second, ``substeps_per_frame`` Bullet steps per frame. The simulation runs at least
``min_simulation_time`` s, then stops at the first check (every ``check_object_interval`` s) where no active object
moved more than the thresholds, or at ``max_simulation_time``.

Differences: hybridgen's rest check is the centre-of-mass shift (m) and turn angle (rad) per check interval, where
BlenderProc compares location and Euler angles one second apart per coordinate; a body's centre of mass is its
collision solid's (Blender: the origin, which BlenderProc moves to the surface centroid); objects that fall more
than 1 m below every passive object stop there (Blender lets them fall on).
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..errors import InputError
from ..physics.settings import PhysicsSettings
from ..physics.simulate import simulate_physics as run_simulation
from ..scene.mesh_object import MeshObject as SceneMesh
from .types import MeshObject
from .types.rigid_body import RigidBody
from .types.mesh_object import get_all_mesh_objects
from .types.unsupported import fail

FPS = 24
"""Blender's default frame rate (frames per second), the clock of its rigid-body world."""
BOX_FACES = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                      [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
"""Outward triangles of the corners ``(x, y, z)`` in ``(0|1, 0|1, 0|1)`` order."""


def _shape(obj: MeshObject, body: RigidBody) -> tuple[str, SceneMesh]:
    """hybridgen's collision shape kind and the mesh it is built from, for one rigid body."""
    mesh = obj.scene_mesh()
    active = body.type == "ACTIVE"
    if body.convex_decomposition:
        return "convex_decomposition", mesh
    if body.collision_shape == "CONVEX_HULL":
        return ("convex_hull" if active else "mesh"), mesh
    if body.collision_shape == "MESH":
        return "mesh", mesh  # active: every triangle collides (Blender's GImpact), hybridgen.physics.mesh_body
    if body.collision_shape == "BOX":
        low, high = mesh.bounds_local
        corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
        box = SceneMesh(obj.get_name(), corners, BOX_FACES, local2world=mesh.local2world)
        return ("convex_hull" if np.all(high - low > 0) or active else "mesh"), box
    if body.collision_shape in PRIMITIVE_SHAPES:
        hull = primitive_hull(body.collision_shape, mesh)
        return "convex_hull", SceneMesh(obj.get_name(), hull.vertices, hull.faces, local2world=mesh.local2world)
    why = {"COMPOUND": "call build_convex_decomposition_collision_shape first"}.get(body.collision_shape, "")
    fail(f"bproc.types.MeshObject.enable_rigidbody(active={active}, collision_shape='{body.collision_shape}')", why)


PRIMITIVE_SHAPES = ("SPHERE", "CAPSULE", "CYLINDER", "CONE")
"""Blender's primitive collision shapes, sized from the object's dimensions (its local bound box; the object's
scale then stretches them) and centred where BlenderProc puts the origin before simulating, the surface centroid:
SPHERE of radius max(dims) / 2; CAPSULE, CYLINDER and CONE along local z, of radius max(dx, dy) / 2 and height dz
(the capsule's too, caps included; the cone's base down). Measured with BlenderProc on bpy 4.2: a 0.4 x 0.6 x 1 m
box with its origin at its bottom face rests, as a capsule, cylinder or cone, with the origin on the ground, and a
0.4 x 1.2 x 0.6 m one, as a sphere, 0.3 m above it. hybridgen simulates each as the convex hull of its surface
(:data:`PRIMITIVE_SEGMENTS` around), where Bullet has exact primitives: a rolling sphere rolls on facets."""
PRIMITIVE_SEGMENTS = 32
MIN_EXTENT = 1e-4
"""m: the least radius and height of a primitive shape (an object flat along an axis)."""


def primitive_hull(shape: str, mesh: SceneMesh) -> Any:
    """The convex hull (a trimesh) of Blender's primitive collision ``shape`` for ``mesh`` (local coordinates)."""
    import trimesh

    low, high = mesh.bounds_local
    dims = high - low
    centre = _surface_centroid(mesh)
    ring = np.linspace(0.0, 2.0 * np.pi, PRIMITIVE_SEGMENTS, endpoint=False)
    circle = np.stack([np.cos(ring), np.sin(ring)], axis=1)
    # a flat object (a plane) gets a shape MIN_EXTENT thick instead of a degenerate one
    radius, height = max(max(dims[0], dims[1]) / 2.0, MIN_EXTENT), max(float(dims[2]), MIN_EXTENT)
    if shape == "SPHERE":
        points = _ball(max(float(dims.max()) / 2.0, MIN_EXTENT), circle)
    elif shape == "CAPSULE":
        half = max(height / 2.0 - radius, 0.0)
        cap = _ball(radius, circle)
        points = np.concatenate([cap[cap[:, 2] > 0] + [0, 0, half], cap[cap[:, 2] < 0] - [0, 0, half]])
    else:
        rim = np.column_stack([circle * radius, np.full(len(circle), -height / 2.0)])
        top = rim + [0, 0, height] if shape == "CYLINDER" else np.array([[0.0, 0.0, height / 2.0]])
        points = np.concatenate([rim, top])
    return trimesh.convex.convex_hull(np.asarray(points, np.float64) + centre)


def _ball(radius: float, circle: np.ndarray) -> np.ndarray:
    """Points of a sphere of ``radius`` around the origin on 16 latitude rings of ``circle``, none at the poles (the
    hull's bottom and top are small flat caps)."""
    latitudes = np.linspace(-np.pi / 2, np.pi / 2, 17)[:-1] + np.pi / 32
    return np.concatenate([np.column_stack([circle * np.cos(lat), np.full(len(circle), np.sin(lat))])
                           for lat in latitudes]) * radius


def _surface_centroid(mesh: SceneMesh) -> np.ndarray:
    """The area-weighted centroid of ``mesh``'s triangles (local coordinates; the bound box centre without area)."""
    triangles = np.asarray(mesh.vertices, np.float64)[np.asarray(mesh.faces)]
    areas = np.linalg.norm(np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]), axis=1)
    if areas.sum() <= 0:
        low, high = mesh.bounds_local
        return (low + high) / 2.0
    return (triangles.mean(axis=1) * areas[:, None]).sum(axis=0) / areas.sum()


def _simulate(min_simulation_time: float, max_simulation_time: float, check_object_interval: float,
              object_stopped_location_threshold: float, object_stopped_rotation_threshold: float,
              substeps_per_frame: int, solver_iters: int, record: bool) -> tuple[list[MeshObject], list[SceneMesh], list]:
    """Run hybridgen's simulation of the session's rigid bodies: (active objects, their meshes with the final
    poses, the per-frame trajectory when ``record``)."""
    if min_simulation_time >= max_simulation_time:
        raise InputError("max_simulation_time has to be bigger than min_simulation_time")
    world = PhysicsSettings(min_time=float(min_simulation_time), max_time=float(max_simulation_time),
                            check_interval=float(check_object_interval),
                            position_threshold=float(object_stopped_location_threshold),
                            rotation_threshold=float(object_stopped_rotation_threshold),
                            time_step=1.0 / (FPS * int(substeps_per_frame)), solver_iterations=int(solver_iters),
                            record_interval=1.0 / FPS if record else None)
    active, active_meshes, passive_meshes, own = [], [], [], {}
    for obj in get_all_mesh_objects():
        body = obj.get_rigidbody()
        if body is None:
            continue
        kind, mesh = _shape(obj, body)
        mesh.attributes["collision_shape"] = kind
        own[id(mesh)] = dataclasses.replace(world, mass=body.mass, friction=body.friction,
                                            restitution=body.restitution, linear_damping=body.linear_damping,
                                            angular_damping=body.angular_damping,
                                            collision_margin=body.collision_margin)
        if body.type == "ACTIVE":
            active.append(obj)
            active_meshes.append(mesh)
        else:
            passive_meshes.append(mesh)
    if not active:
        return [], [], []
    result = run_simulation(active_meshes, passive_meshes, world, own)
    return active, active_meshes, result.trajectory


def _set_pose(obj: MeshObject, local2world: np.ndarray, frame: int | None = None) -> None:
    """Location and rotation of ``local2world`` (its scale is the object's own), keyed at ``frame``."""
    linear = local2world[:3, :3]
    obj.set_location(local2world[:3, 3], frame)
    obj.set_rotation_mat(linear / np.linalg.norm(linear, axis=0), frame)


def simulate_physics_and_fix_final_poses(min_simulation_time: float = 4.0, max_simulation_time: float = 40.0,
                                         check_object_interval: float = 2.0,
                                         object_stopped_location_threshold: float = 0.01,
                                         object_stopped_rotation_threshold: float = 0.1, substeps_per_frame: int = 10,
                                         solver_iters: int = 10, verbose: bool = False,
                                         use_volume_com: bool = False) -> None:
    """Simulate (see the module documentation) and give every active object its final location and rotation (its
    mesh and origin unchanged). ``verbose`` and ``use_volume_com`` change nothing here."""
    active, meshes, _ = _simulate(min_simulation_time, max_simulation_time, check_object_interval,
                                  object_stopped_location_threshold, object_stopped_rotation_threshold,
                                  substeps_per_frame, solver_iters, record=False)
    for obj, mesh in zip(active, meshes):
        if obj.get_parent() is None:
            _set_pose(obj, mesh.local2world)
        else:
            obj.set_local2world_mat(mesh.local2world)


def simulate_physics(min_simulation_time: float = 4.0, max_simulation_time: float = 40.0,
                     check_object_interval: float = 2.0, object_stopped_location_threshold: float = 0.01,
                     object_stopped_rotation_threshold: float = 0.1, substeps_per_frame: int = 10,
                     solver_iters: int = 10, verbose: bool = False, use_volume_com: bool = False) -> dict[str, np.ndarray]:
    """Simulate and keep the motion as an animation, as Blender's baked rigid-body cache shows it: the active
    objects' location and rotation keyed at frames 1, 2, ... (frame ``k`` shows the simulation at ``(k - 1) / 24``
    s). First, as BlenderProc does, every rigid-body object's origin moves to its surface centroid and its scale
    is baked into its mesh; returns ``{name: new origin - old origin}`` (world, m) of those objects."""
    if use_volume_com:
        fail("bproc.object.simulate_physics(use_volume_com=True)")
    shifts = {}
    for obj in get_all_mesh_objects():
        if obj.has_rigidbody_enabled():
            before = obj.get_origin()
            shifts[obj.get_name()] = obj.set_origin(mode="CENTER_OF_MASS") - before
            obj.persist_transformation_into_mesh(location=False, rotation=False, scale=True)
    active, _, trajectory = _simulate(min_simulation_time, max_simulation_time, check_object_interval,
                                      object_stopped_location_threshold, object_stopped_rotation_threshold,
                                      substeps_per_frame, solver_iters, record=True)
    for frame, poses in enumerate(trajectory, start=1):
        for obj, pose in zip(active, poses):
            _set_pose(obj, pose, frame)
    return shifts
