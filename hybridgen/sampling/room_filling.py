"""Filling a random room's floor with objects, as BlenderProc's RandomRoomConstructor does: a round robin over the
floor plan's pieces (:mod:`hybridgen.scene.room_plan`) placing a copy of each model every ``step`` m^2 of floor,
each placement a few uniform poses on the piece tested against the room's walls and ceiling and everything placed
before (exact mesh tests, :class:`~hybridgen.scene.collision.CollisionWorld`).

A model is a group of hybridgen meshes that move as one (the parts of one loaded model). A placement puts the
group's reference origin on the floor (z = 0) at a uniform point of the piece with a uniform turn about Z (x and y
rotation 0, scale kept). Units: metres, radians, world Z up.
"""
from __future__ import annotations

from typing import Callable, Sequence, TypeVar

import numpy as np

from ..scene.collision import CollisionWorld
from ..scene.frames import object_pose
from ..scene.mesh_object import MeshObject
from ..scene.room_plan import Rect
from .placement import scale_of

Group = TypeVar("Group")


class RoomPlacer:
    """Tries poses of object groups on floor pieces against the room's ``obstacles`` and what it placed."""

    def __init__(self, obstacles: Sequence[MeshObject], tries: int, rng: np.random.Generator) -> None:
        self.world = CollisionWorld(list(obstacles))
        self.tries = tries
        self.rng = rng
        self.placed: list[list[MeshObject]] = []

    def try_piece(self, group: list[MeshObject], piece: Rect) -> bool:
        """Up to ``tries`` poses of ``group`` on ``piece``; the first free one is applied (each part's
        ``local2world``), and True. The group's first part is the reference whose origin lands on the floor."""
        rng = self.rng
        reference = group[0].local2world
        for _ in range(self.tries):
            location = [rng.uniform(piece[0], piece[2]), rng.uniform(piece[1], piece[3]), 0.0]
            turn = rng.uniform(0.0, 2.0 * np.pi)
            moved = object_pose(location, [0.0, 0.0, turn], scale_of(group[0])) @ np.linalg.inv(reference)
            poses = [moved @ part.local2world for part in group]
            if any(self.world.collides(part, pose) for part, pose in zip(group, poses)):
                continue
            for part, pose in zip(group, poses):
                part.local2world = pose
                self.world.add(part)
            self.placed.append(group)
            return True
        return False


def fill_round_robin(pieces: Sequence[Rect], models: Sequence[Group], objects_per_sq_meter: float,
                     rng: np.random.Generator, place: Callable[[Group, Rect], bool],
                     duplicate: Callable[[Group], Group]) -> list[Group]:
    """BlenderProc's round robin over ``models`` in the given order (BlenderProc: biggest bounding box first):
    each walks the pieces from a random one, placing (``place``) a copy every ``step`` m^2 of floor (step =
    models / ``objects_per_sq_meter``); after a successful placement the next copy is ``duplicate`` of it.
    When ``step`` exceeds the floor area some models are skipped. Returns the last copy of each model that was
    placed at least once (not placed itself: the caller removes it)."""
    leftovers: list[Group] = []
    if not models:
        return leftovers
    sizes = [(r[2] - r[0]) * (r[3] - r[1]) for r in pieces]
    total = sum(sizes)
    step = len(models) / objects_per_sq_meter
    counter = rng.uniform(-step, step)
    for model in models:
        current = model
        if step > total:  # fewer placements than models: some models are skipped
            counter += total
            if counter > step:
                counter = rng.uniform(-step, step)
                continue
        walked = 0.0
        i = int(rng.integers(len(pieces)))
        accumulated = rng.uniform(0.0, step + 1e-7)
        while walked < total:
            size = sizes[i]
            if size < step:
                accumulated += size
                placements = 1 if accumulated > step else 0
                accumulated -= step * placements
            else:
                placements = int((size + accumulated) / step)
                accumulated = size - placements * step
            for _ in range(placements):
                if place(current, pieces[i]):
                    current = duplicate(current)
            i = (i + 1) % len(pieces)
            walked += size
        if current is not model:
            leftovers.append(current)
    return leftovers
