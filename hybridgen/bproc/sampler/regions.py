"""``bproc.sampler`` samplers over objects' extents: ``upper_region`` and the point-in-room samplers.

They read objects through the methods BlenderProc's ``MeshObject`` has, so any object with them works:

- ``get_bound_box()``: the 8 corners (8x3, world metres) of the object's local bounding box, in Blender's
  corner order: corner i has x = max if i & 4, y = max if i in (2, 3, 6, 7), z = max if i in (1, 2, 5, 6);
- ``get_local2world_mat()`` and ``ray_cast(origin, direction)`` (local frame, returning ``(hit, location,
  normal, face_index)``) for ``upper_region(use_ray_trace_check=True)``;
- ``get_name()``, ``get_location()``, ``has_cp(key)``, ``position_is_above_object(point)`` for the rooms.

Draws come from Python's ``random`` module, in BlenderProc 2.8's order. Points are world metres, (3,) arrays.
"""
from __future__ import annotations

import ast
import math
import random
from typing import Any, Optional, Sequence

import numpy as np

__all__ = ["Front3DPointInRoomSampler", "ReplicaPointInRoomSampler", "SuncgPointInRoomSampler", "upper_region"]

_BOX_FACES = ((0, 1, 2, 3), (0, 4, 5, 1), (1, 5, 6, 2), (6, 7, 3, 2), (3, 7, 4, 0), (7, 6, 5, 4))
"""The bounding box's faces as corner indices, each wound so that (c1 - c0) x (c3 - c0) points outwards."""


def _face_frame(corners: np.ndarray, face: Sequence[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(base corner, first edge, second edge, unit normal) of one bounding-box face (metres)."""
    base = corners[face[0]]
    first, second = corners[face[1]] - base, corners[face[3]] - base
    normal = np.cross(first, second)
    length = np.linalg.norm(normal)
    return base, first, second, normal / length if length > 0 else normal  # a flat box's side faces: zero


def _upper_face(obj: Any, up: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The face of ``obj``'s bounding box whose outward normal is closest to ``up`` (the first on a tie)."""
    corners = np.asarray(obj.get_bound_box(), dtype=np.float64)
    frames = [_face_frame(corners, face) for face in _BOX_FACES]
    angles = [math.acos(float(np.clip(frame[3].dot(up), -1.0, 1.0))) if frame[3].any() else math.inf
              for frame in frames]  # a degenerate face (a plane's bounding box has no height) is never chosen
    return frames[int(np.argmin(angles))]


def upper_region(objects_to_sample_on: Any, face_sample_range: Optional[Sequence[float]] = None,
                 min_height: float = 0.0, max_height: float = 1.0, use_ray_trace_check: bool = False,
                 upper_dir: Optional[Sequence[float]] = None, use_upper_dir: bool = True) -> np.ndarray:
    """A point above one of the objects: on the face of its bounding box that faces ``upper_dir`` (default
    +Z) most, raised by ``min_height..max_height`` metres along ``upper_dir`` (or along the face's normal
    when ``use_upper_dir`` is false).

    ``face_sample_range`` (default ``[0, 1]``) is the fraction of each face edge to sample along. Draws: the
    object (``random.randint``), then per try the two edge fractions and the height (``random.uniform``).
    With ``use_ray_trace_check`` a try counts only when a ray from the point down the sampling direction hits
    the object itself (its ``ray_cast``); otherwise the first try is returned.
    """
    span = np.array([0.0, 1.0] if face_sample_range is None else face_sample_range, dtype=np.float64)
    up = np.array([0.0, 0.0, 1.0] if upper_dir is None else upper_dir, dtype=np.float64)
    up /= np.linalg.norm(up)
    objects = objects_to_sample_on if isinstance(objects_to_sample_on, list) else [objects_to_sample_on]
    if max_height < min_height:
        raise ValueError(f"bproc.sampler.upper_region: min_height ({min_height}) must be smaller than "
                         f"max_height ({max_height})")
    if not objects:
        raise ValueError("bproc.sampler.upper_region: no objects to sample on")
    faces = [_upper_face(obj, up) for obj in objects]
    chosen = random.randint(0, len(objects) - 1)
    base, first, second, normal = faces[chosen]
    direction = up if use_upper_dir else normal
    world2local = np.linalg.inv(objects[chosen].get_local2world_mat()) if use_ray_trace_check else None
    while True:
        point = base.copy()
        for edge in (first, second):
            point += edge * random.uniform(span[0], span[1])
        point += direction * random.uniform(min_height, max_height)
        if world2local is None:
            return point
        origin = world2local @ np.append(point, 1.0)
        down = world2local @ np.append(-direction, 0.0)
        if objects[chosen].ray_cast(origin[:3], down[:3])[0]:
            return point


class Front3DPointInRoomSampler:
    """Points inside the rooms of a loaded 3D-FRONT scene: above a floor object of a room that has more
    than ``amount_of_objects_needed_per_room`` furniture objects (those with the custom property
    ``is_3D_future``, not walls or ceilings, whose location is above that floor)."""

    def __init__(self, front3d_objects: list[Any], amount_of_objects_needed_per_room: int = 2) -> None:
        future = [obj for obj in front3d_objects if obj.has_cp("is_3D_future")]
        floors = [obj for obj in future if obj.get_name().lower().startswith("floor")]
        counts = {floor.get_name(): 0 for floor in floors}
        for obj in future:
            name = obj.get_name().lower()
            if "wall" in name or "ceiling" in name:
                continue
            for floor in floors:
                if floor.position_is_above_object(obj.get_location()):
                    counts[floor.get_name()] += 1
        self.used_floors = [floor for floor in floors if counts[floor.get_name()] > amount_of_objects_needed_per_room]

    def sample(self, height: float, max_tries: int = 1000) -> np.ndarray:
        """A point ``height`` metres above a room's floor, uniform in x/y over that floor's bounding box:
        per try a floor (``random.choice``), then x and y (``random.uniform``), kept when above the floor."""
        for _ in range(max_tries):
            floor = random.choice(self.used_floors)
            corners = np.asarray(floor.get_bound_box(), dtype=np.float64)
            low, high = corners.min(axis=0), corners.max(axis=0)
            point = np.array([random.uniform(low[0], high[0]), random.uniform(low[1], high[1]),
                              floor.get_location()[2] + height])
            if floor.position_is_above_object(point):
                return point
        raise RuntimeError(f"Front3DPointInRoomSampler: no point above a room's floor in {max_tries} tries")


class ReplicaPointInRoomSampler:
    """Points inside a Replica room: uniform in x/y over ``room_bounding_box`` (``{"min": xyz, "max": xyz}``,
    metres), at one of the floor heights listed (a Python literal list) in ``height_list_file_path``."""

    def __init__(self, room_bounding_box: dict[str, Any], replica_floor: Any, height_list_file_path: str) -> None:
        if isinstance(replica_floor, list) and not replica_floor:
            raise ValueError("ReplicaPointInRoomSampler: the floor object list is empty")
        self.bounding_box = room_bounding_box
        self.floor_object = replica_floor
        with open(height_list_file_path, "r", encoding="utf-8") as file:
            self.floor_height_values = [float(value) for value in ast.literal_eval(file.read())]

    def sample(self, height: float, max_tries: int = 1000) -> np.ndarray:
        """A point ``height`` metres above a listed floor height: per try x, y (``random.uniform``) and a
        floor height (``random.randrange``), kept when above a floor object."""
        floors = self.floor_object if isinstance(self.floor_object, list) else [self.floor_object]
        low, high = self.bounding_box["min"], self.bounding_box["max"]
        for _ in range(max_tries):
            point = np.array([random.uniform(low[0], high[0]), random.uniform(low[1], high[1]),
                              self.floor_height_values[random.randrange(0, len(self.floor_height_values))] + height])
            if any(floor.position_is_above_object(point) for floor in floors):
                return point
        raise RuntimeError(f"ReplicaPointInRoomSampler: no point above the floor in {max_tries} tries")


class SuncgPointInRoomSampler:
    """SUNCG's room sampler: SUNCG was withdrawn by its authors, so hybridgen loads no SUNCG scenes."""

    def __init__(self, suncg_objects: list[Any]) -> None:
        raise NotImplementedError("bproc.sampler.SuncgPointInRoomSampler is not supported: the SUNCG data set "
                                  "was withdrawn and hybridgen has no SUNCG loader")
