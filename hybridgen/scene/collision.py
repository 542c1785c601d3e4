"""Exact mesh-mesh collision tests between scene objects (FCL through trimesh's CollisionManager).

Triangles of two posed meshes intersect or they don't: no bounding-box approximation. (A mesh entirely
inside another without touching its surface is not a collision for this test.) ``python-fcl`` is imported
when a test is first made, with an actionable error when it is missing.
"""
from __future__ import annotations

from typing import Any, Iterable

import numpy as np

from ..errors import SystemSetupError
from .mesh_object import MeshObject


def _manager() -> Any:
    try:
        import fcl  # noqa: F401
    except ImportError:
        raise SystemSetupError("collision checks need python-fcl: `.venv/bin/pip install python-fcl`") from None
    import trimesh

    return trimesh.collision.CollisionManager()


def _posed(obj: MeshObject, pose: np.ndarray) -> tuple[Any, np.ndarray]:
    """The mesh with the pose's linear part (rotation and any scale) baked in, and the rigid remainder.

    FCL transforms are rigid; object poses may scale."""
    import trimesh

    translation = np.eye(4)
    translation[:3, 3] = pose[:3, 3]
    return trimesh.Trimesh(obj.vertices @ pose[:3, :3].T, obj.faces, process=False), translation


class CollisionWorld:
    """Objects that others must not intersect, each at the pose it had when added."""

    def __init__(self, objects: Iterable[MeshObject] = ()) -> None:
        self._manager = _manager()
        self._names: set[str] = set()
        for obj in objects:
            self.add(obj)

    @staticmethod
    def _key(obj: MeshObject) -> str:
        return f"{obj.instance_id}:{id(obj)}"

    def add(self, obj: MeshObject) -> None:
        """Add ``obj`` at its current pose (re-adding an object moves it there)."""
        self.remove(obj)
        mesh, rigid = _posed(obj, obj.local2world)
        key = self._key(obj)
        self._manager.add_object(key, mesh, transform=rigid)
        self._names.add(key)

    def remove(self, obj: MeshObject) -> None:
        key = self._key(obj)
        if key in self._names:
            self._manager.remove_object(key)
            self._names.discard(key)

    def collides(self, obj: MeshObject, pose: np.ndarray | None = None) -> bool:
        """Would ``obj`` at ``pose`` (default: its own) intersect any object of this world other than itself?"""
        mesh, rigid = _posed(obj, obj.local2world if pose is None else pose)
        hit, names = self._manager.in_collision_single(mesh, transform=rigid, return_names=True)
        return bool(hit and (names - {self._key(obj)}))
