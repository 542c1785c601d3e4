"""A PyBullet DIRECT client holding the bodies of one simulation (PyBullet imported on first use)."""
from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import InputError, SystemSetupError
from ..scene.frames import make_pose
from ..scene.mesh_object import MeshObject
from .bodies import Body, shape_of
from .settings import PhysicsSettings
from .shapes import CollisionGeometry, collision_geometry


def pybullet_module() -> Any:
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


def write_obj(path: str, parts: Sequence[tuple[np.ndarray, np.ndarray]]) -> None:
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


class BulletWorld:
    """A PyBullet DIRECT client holding the bodies of one simulation."""

    def __init__(self, settings: PhysicsSettings, workdir: str, substeps: int) -> None:
        self.pb = pybullet_module()
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
        write_obj(path, parts)
        return path

    def shape(self, geometry: CollisionGeometry, parts: list[tuple[np.ndarray, np.ndarray]]) -> int:
        """A collision shape: a static triangle mesh, one convex hull, or a compound of convex hulls (also one
        per triangle of a moving mesh, :mod:`hybridgen.physics.mesh_body`)."""
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

    def add_static(self, obj: MeshObject, settings: PhysicsSettings | None = None) -> int:
        """A passive body of ``obj`` with ``settings`` (default: the world's) for its shape and dynamics."""
        s = settings or self.settings
        kind = shape_of(obj, s.passive_shape, active=False)
        try:
            geometry = collision_geometry(obj.vertices, obj.faces, kind, obj.local2world[:3, :3], s.decomposition,
                                          active=False)
        except InputError as exc:
            raise InputError(f"passive object '{obj.name}': {exc}") from None
        shape = self.shape(geometry, geometry.parts)
        body = self.pb.createMultiBody(0.0, shape, basePosition=obj.local2world[:3, 3].tolist(),
                                       physicsClientId=self.client)
        self._dynamics(body, s)
        return body

    def add_active(self, body: Body) -> None:
        from scipy.spatial.transform import Rotation

        shape = self.shape(body.geometry, body.body_parts())
        quaternion = Rotation.from_matrix(body.start[:3, :3]).as_quat()  # x, y, z, w as PyBullet
        body.id = self.pb.createMultiBody(body.mass, shape, basePosition=body.start[:3, 3].tolist(),
                                          baseOrientation=quaternion.tolist(),
                                          physicsClientId=self.client)
        self._dynamics(body.id, body.settings, mass=body.mass, localInertiaDiagonal=body.principal.tolist())

    def _dynamics(self, body: int, s: PhysicsSettings, **extra: Any) -> None:
        self.pb.changeDynamics(body, -1, lateralFriction=s.friction, restitution=s.restitution,
                               rollingFriction=s.rolling_friction, spinningFriction=s.spinning_friction,
                               linearDamping=s.linear_damping, angularDamping=s.angular_damping,
                               collisionMargin=s.collision_margin, physicsClientId=self.client, **extra)

    def pose(self, body: int) -> np.ndarray:
        from scipy.spatial.transform import Rotation

        position, quaternion = self.pb.getBasePositionAndOrientation(body, physicsClientId=self.client)
        return make_pose(Rotation.from_quat(quaternion).as_matrix(), np.asarray(position))
