"""``bproc.object.create_bvh_tree_multi_objects`` and ``scene_ray_cast`` (BlenderProc's MeshObjectUtility) over
:class:`hybridgen.scene.ray_casting.RayCaster`; the tree is :class:`hybridgen.bproc.types.bvh_tree.BVHTree`."""
from __future__ import annotations

from typing import Sequence

from ..scene.ray_casting import RayCaster
from .types.bvh_tree import BVHTree
from .types.mesh_geometry import scene_ray_cast
from .types.mesh_object import MeshObject

__all__ = ["BVHTree", "create_bvh_tree_multi_objects", "scene_ray_cast"]


def create_bvh_tree_multi_objects(mesh_objects: Sequence[MeshObject]) -> BVHTree:
    """One tree of the given objects' triangles in world coordinates at their current poses."""
    return BVHTree(RayCaster([obj.world_triangles() for obj in mesh_objects]))
