"""``bproc.constructor``: ``construct_random_room`` (BlenderProc's RandomRoomConstructor) over hybridgen's floor plan
(:mod:`hybridgen.scene.room_plan`) and round-robin filling (:mod:`hybridgen.sampling.room_filling`), the same core
as hybridgen's ``constructor.RandomRoomConstructor`` module.

Units: metres, m^2, radians; world Z up, the floor at z = 0 and the plan centred on the origin. Random draws come
from Python's ``random`` (as BlenderProc's constructor draws), through one numpy generator seeded from it.
"""
from __future__ import annotations

import random
from typing import Sequence

import numpy as np

from ..errors import InputError
from ..sampling.room_filling import RoomPlacer, fill_round_robin
from ..scene.mesh_object import MeshObject as ScenePart
from ..scene.room_plan import Rect, random_plan, room_meshes
from .object import delete_multiple
from .types import Material, MeshObject

__all__ = ["construct_random_room"]


def _room_object(name: str, mesh: tuple[np.ndarray, np.ndarray, np.ndarray]) -> MeshObject:
    """A mesh object of world-frame room geometry (identity pose; cube-projected UVs, one repeat per metre)."""
    vertices, faces, uvs = mesh
    return MeshObject(name, [ScenePart(name, vertices, faces, uvs=uvs)])


def construct_random_room(used_floor_area: float, interior_objects: list[MeshObject], materials: Sequence[Material],
                          amount_of_extrusions: int = 0, fac_from_square_room: float = 0.3,
                          corridor_width: float = 0.9, wall_height: float = 2.5, amount_of_floor_cuts: int = 2,
                          only_use_big_edges: bool = True, create_ceiling: bool = True,
                          assign_material_to_ceiling: bool = False, placement_tries_per_face: int = 3,
                          amount_of_objects_per_sq_meter: float = 3.0) -> list[MeshObject]:
    """A random room of ``used_floor_area`` m^2 (a rectangle whose sides differ from a square's by up to
    ``fac_from_square_room``, plus up to ``amount_of_extrusions`` corridors at least ``corridor_width`` m wide)
    with walls ``wall_height`` m high, filled with ``interior_objects``: the objects ``Wall``, ``Ceiling`` (with
    ``create_ceiling``, and always for a plain rectangle, as BlenderProc's extrusion closes it) and ``Floor``,
    every surface facing into the room. Floor and walls (and the ceiling with ``assign_material_to_ceiling``)
    each get a random one of ``materials``. ``interior_objects`` is sorted in place, biggest bound box first, and
    placed round robin over the floor (origin on z = 0, a uniform turn about Z, ``placement_tries_per_face``
    tries per placement, about ``amount_of_objects_per_sq_meter`` placements per m^2), each placed object
    duplicated for the next placement; objects never placed and the unused last copies are deleted.

    Returns ``[Wall, Ceiling?, placed objects in placement order..., Floor]``, as BlenderProc."""
    if not float(amount_of_objects_per_sq_meter) > 0:
        raise InputError(f"amount_of_objects_per_sq_meter must be > 0, got {amount_of_objects_per_sq_meter}")
    rng = np.random.default_rng(random.getrandbits(64))
    pieces = random_plan(float(used_floor_area), int(amount_of_extrusions), float(fac_from_square_room),
                         float(corridor_width), int(amount_of_floor_cuts), bool(only_use_big_edges), rng)
    meshes = room_meshes(pieces, float(wall_height))
    wall = _room_object("Wall", meshes.walls)
    ceiling = _room_object("Ceiling", meshes.ceiling) if create_ceiling or int(amount_of_extrusions) == 0 else None
    floor = _room_object("Floor", meshes.floor)
    if materials:
        floor.replace_materials(random.choice(materials))
        wall.replace_materials(random.choice(materials))
        if ceiling is not None and assign_material_to_ceiling:
            ceiling.replace_materials(random.choice(materials))
    placed: list[MeshObject] = [wall] + ([ceiling] if ceiling is not None else [])
    placer = RoomPlacer([obj.scene_mesh() for obj in placed], int(placement_tries_per_face), rng)

    def place(obj: MeshObject, piece: Rect) -> bool:
        mesh = obj.scene_mesh()
        if not placer.try_piece([mesh], piece):
            return False
        obj.set_location(mesh.local2world[:3, 3])
        obj.set_rotation_euler([0.0, 0.0, float(np.arctan2(mesh.local2world[1, 0], mesh.local2world[0, 0]))])
        placed.append(obj)
        return True

    interior_objects.sort(key=lambda obj: obj.get_bound_box_volume())
    interior_objects.reverse()
    leftovers = fill_round_robin(pieces, interior_objects, float(amount_of_objects_per_sq_meter), rng, place,
                                 lambda obj: obj.duplicate())
    delete_multiple(leftovers + [obj for obj in interior_objects if obj not in placed], remove_all_offspring=True)
    return placed + [floor]

