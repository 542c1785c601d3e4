"""Points inside the rooms of a loaded indoor scene, as BlenderProc's room camera samplers draw camera places.

- :func:`object_below`: the object a ray cast from a point straight down (world -Z) hits first - BlenderProc's
  ``position_is_above_object`` (exact: a vertical ray needs only a 2D point-in-triangle test and the
  triangle's height there).
- :class:`Front3DRoomPoints`: BlenderProc's ``Front3DPointInRoomSampler``. The rooms are the 3D-FRONT floors
  (objects with the ``is_3D_future`` attribute whose name starts with ``floor``, any case); a room is used when
  more than ``min_objects`` of the other 3D-FRONT objects (walls and ceilings not counted) stand above it (the
  ray from the object's origin, ``local2world``'s translation, hits that floor first; the object itself is
  skipped by its own ray). A point: a used floor drawn uniformly, x and y uniform in its bounding box, z = the
  floor object's origin z + ``height``, kept when it stands above that floor (up to 1000 tries).
- :class:`ReplicaRoomPoints`: BlenderProc's ``ReplicaPointInRoomSampler``. x and y uniform in the scene mesh's
  bounding box, z = one of the scene's floor heights (drawn uniformly from the height list) + ``height``, kept
  when the point stands above the extracted floor object (up to 1000 tries).

Heights and coordinates are metres in world axes (Z up). Draws use the given NumPy generator.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import ConfigError, InputError
from ..scene.mesh_object import MeshObject

MAX_TRIES = 1000
"""Points tried per draw before giving up (BlenderProc's ``max_tries``)."""

_EPSILON = 1e-6
"""m: a surface this far above the ray's start still counts as hit (a point lying on a floor is above it)."""


@dataclass
class _Triangles:
    """World-space triangles of one object with their xy bounding box."""

    obj: MeshObject
    corners: np.ndarray  # (F, 3, 3)
    low: np.ndarray  # (2,) xy minimum
    high: np.ndarray  # (2,) xy maximum


class DownwardRays:
    """Casts vertical rays (world -Z) against a fixed set of objects."""

    def __init__(self, objects: Sequence[MeshObject]) -> None:
        self._objects = []
        for obj in objects:
            corners = obj.world_vertices()[obj.faces]
            xy = corners[..., :2].reshape(-1, 2)
            self._objects.append(_Triangles(obj, corners, xy.min(axis=0), xy.max(axis=0)))

    def object_below(self, point: np.ndarray, skip: MeshObject | None = None) -> MeshObject | None:
        """The object a ray from ``point`` straight down hits first (None: nothing below); ``skip`` is
        transparent to the ray."""
        x, y, z = (float(c) for c in point)
        best, best_z = None, -np.inf
        for entry in self._objects:
            if entry.obj is skip or not (entry.low[0] <= x <= entry.high[0] and entry.low[1] <= y <= entry.high[1]):
                continue
            heights = _heights_at(entry.corners, x, y)
            heights = heights[heights <= z + _EPSILON]
            if len(heights) and heights.max() > best_z:
                best, best_z = entry.obj, float(heights.max())
        return best

    def is_above(self, point: np.ndarray, obj: MeshObject) -> bool:
        """BlenderProc's ``position_is_above_object``: the ray straight down from ``point`` hits ``obj`` first."""
        return self.object_below(point) is obj


def _heights_at(corners: np.ndarray, x: float, y: float) -> np.ndarray:
    """z of every non-vertical triangle of ``corners`` (F, 3, 3) whose xy projection holds (x, y)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    v0, v1 = b[:, :2] - a[:, :2], c[:, :2] - a[:, :2]
    det = v0[:, 0] * v1[:, 1] - v0[:, 1] * v1[:, 0]
    px, py = x - a[:, 0], y - a[:, 1]
    safe = np.where(np.abs(det) > 1e-15, det, 1.0)
    s = (px * v1[:, 1] - py * v1[:, 0]) / safe
    t = (v0[:, 0] * py - v0[:, 1] * px) / safe
    inside = (np.abs(det) > 1e-15) & (s >= -1e-12) & (t >= -1e-12) & (s + t <= 1 + 1e-12)
    z = a[:, 2] + s * (b[:, 2] - a[:, 2]) + t * (c[:, 2] - a[:, 2])
    return z[inside]


def _world_box(obj: MeshObject) -> np.ndarray:
    points = obj.world_vertices()
    return np.stack([points.min(axis=0), points.max(axis=0)])


class Front3DRoomPoints:
    """Camera places in the rooms of a loaded 3D-FRONT house (see the module doc)."""

    def __init__(self, objects: Sequence[MeshObject], min_objects: int = 2) -> None:
        front = [o for o in objects if "is_3D_future" in o.attributes]
        self.rays = DownwardRays(objects)
        floors = [o for o in front if o.name.lower().startswith("floor")]
        counts = {id(floor): 0 for floor in floors}
        for obj in front:
            name = obj.name.lower()
            if "wall" in name or "ceiling" in name:
                continue
            below = self.rays.object_below(obj.local2world[:3, 3], skip=obj)
            if below is not None and id(below) in counts:
                counts[id(below)] += 1
        self.counts = [(floor.name, counts[id(floor)]) for floor in floors]  # per floor, in scene order
        self.floors = [floor for floor in floors if counts[id(floor)] > min_objects]
        if not self.floors:
            detail = ", ".join(f"{name}: {count}" for name, count in self.counts) or "no 3D-FRONT floor"
            raise InputError(f"no room has more than {min_objects} objects standing on its floor ({detail}); "
                             "load a 3D-FRONT house first (loader.Front3DLoader) or lower "
                             "amount_of_objects_needed_per_room")
        self._boxes = [_world_box(floor) for floor in self.floors]

    def sample(self, height: float, rng: np.random.Generator) -> tuple[np.ndarray, MeshObject]:
        """A point ``height`` m above the origin of a used floor, straight above that floor; and the floor."""
        for _ in range(MAX_TRIES):
            index = int(rng.integers(len(self.floors)))
            floor, box = self.floors[index], self._boxes[index]
            point = np.array([rng.uniform(box[0, 0], box[1, 0]), rng.uniform(box[0, 1], box[1, 1]),
                              floor.local2world[2, 3] + height])
            if self.rays.is_above(point, floor):
                return point, floor
        raise InputError(f"no point {height} m above a room's floor is straight above it in {MAX_TRIES} tries")


def read_height_list(path: Path, key: str) -> list[float]:
    """A Replica height list file: a Python/JSON list of floor heights (m), e.g. ``[-1.54, 1.309]``."""
    if not path.is_file():
        raise ConfigError(f"height list file not found: '{path}'", key=key)
    try:
        values = [float(v) for v in ast.literal_eval(path.read_text())]
    except (ValueError, TypeError, SyntaxError):
        raise ConfigError(f"'{path}' is not a list of numbers (e.g. [-1.54, 1.309])", key=key) from None
    if not values:
        raise ConfigError(f"'{path}' lists no height", key=key)
    return values


class ReplicaRoomPoints:
    """Camera places in a loaded Replica scene (see the module doc)."""

    def __init__(self, objects: Sequence[MeshObject], mesh: MeshObject, floor: MeshObject,
                 floor_heights: Sequence[float]) -> None:
        self.rays = DownwardRays(objects)
        self.floor = floor
        self.box = _world_box(mesh)
        self.floor_heights = [float(h) for h in floor_heights]

    def sample(self, height: float, rng: np.random.Generator) -> np.ndarray:
        """A point ``height`` m above one of the floor heights, straight above the floor object."""
        for _ in range(MAX_TRIES):
            point = np.array([rng.uniform(self.box[0, 0], self.box[1, 0]), rng.uniform(self.box[0, 1], self.box[1, 1]),
                              self.floor_heights[int(rng.integers(len(self.floor_heights)))] + height])
            if self.rays.is_above(point, self.floor):
                return point
        raise InputError(f"no point {height} m above the floor heights {self.floor_heights} is straight above "
                         f"the floor object '{self.floor.name}' in {MAX_TRIES} tries")
