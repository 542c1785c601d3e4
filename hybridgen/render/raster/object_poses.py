"""Per-object matrices of a raster draw, from the scene's object poses and the keypoint's camera (NumPy; no GL).

The camera-independent part (local2world, its inverse, normal matrices, winding, local bounds) is cached until an
object moves; per keypoint, every object's modelview, normal matrix, cull flag and front-face winding come from it
in a few batched products.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np


class ObjectPoses:
    """The draws' per-object uniforms of one raster view's objects (``gpu_objects`` in the scene's order)."""

    def __init__(self, scene_objects: Sequence[Any]) -> None:
        self.scene_objects = scene_objects
        self._cached_pose_key: bytes | None = None
        self._cached_pose: dict[str, Any] = {}

    def draws(self, gpu_objects: Sequence[Any], cam2world: np.ndarray, world2cam: np.ndarray, near_reach: float,
              hidden: frozenset[int]) -> list[tuple[Any, ...]]:
        """Per object to draw: modelview and normal matrix (float32 bytes, column-major), cull flag, the
        front-face winding and (float64 modelview, camera centre in object-local coordinates) - computed for
        all objects at once from cached per-pose values."""
        cache = self._pose_cache(gpu_objects)
        if not cache["objects"]:
            return []
        modelview = np.einsum("ij,njk->nik", world2cam, cache["local2world"])
        normal_to_cam = np.einsum("ij,njk->nik", world2cam[:3, :3], cache["normal_to_world"])
        cam_local = np.einsum("nij,j->ni", cache["to_local"][:, :3, :3], cam2world[:3, 3]) + cache["to_local"][:, :3, 3]
        bounds = cache["bounds"]
        gap = np.maximum(np.maximum(bounds[:, 0] - cam_local, cam_local - bounds[:, 1]), 0.0)
        outside = np.linalg.norm(gap, axis=1) > near_reach * cache["stretch"]
        modelview_bytes = np.ascontiguousarray(modelview.transpose(0, 2, 1), dtype=np.float32)
        normal_bytes = np.ascontiguousarray(normal_to_cam.transpose(0, 2, 1), dtype=np.float32)
        draws = []
        for i, gpu in enumerate(cache["objects"]):
            if gpu.instance_id in hidden:
                continue
            draws.append((gpu, modelview_bytes[i].tobytes(), normal_bytes[i].tobytes(),
                          bool(gpu.closed and outside[i]), "cw" if cache["det"][i] > 0 else "ccw",
                          (modelview[i], cam_local[i])))
        return draws

    def _pose_cache(self, gpu_objects: Sequence[Any]) -> dict[str, Any]:
        """Camera-independent per-object matrices, recomputed only when an object's pose changed."""
        key = b"".join(obj.local2world.tobytes() for obj in self.scene_objects)
        if self._cached_pose_key != key:
            pairs = [(gpu, obj) for gpu, obj in zip(gpu_objects, self.scene_objects)
                     if np.linalg.det(obj.local2world[:3, :3]) != 0]  # zero scale: nothing to draw
            local2world = np.array([obj.local2world for _, obj in pairs]).reshape(-1, 4, 4)
            to_local = np.linalg.inv(local2world) if len(pairs) else local2world
            self._cached_pose = {
                "objects": [gpu for gpu, _ in pairs], "local2world": local2world, "to_local": to_local,
                "normal_to_world": to_local[:, :3, :3].transpose(0, 2, 1),
                "det": np.linalg.det(local2world[:, :3, :3]) if len(pairs) else np.zeros(0),
                "bounds": np.array([gpu.bounds for gpu, _ in pairs]).reshape(-1, 2, 3),
                # a world distance d is at most d * |to_local|_2 in local units
                "stretch": np.linalg.norm(to_local[:, :3, :3], ord=2, axis=(1, 2)) if len(pairs) else np.zeros(0),
            }
            self._cached_pose_key = key
        return self._cached_pose
