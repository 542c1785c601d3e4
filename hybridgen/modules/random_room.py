"""``constructor.RandomRoomConstructor``: a random room (floor, walls, ceiling) filled with loaded objects.

As BlenderProc runs it: the loaders of ``used_loader_config`` run first (each ``amount_of_repetitions``
times); then a floor plan of ``floor_area`` m^2 is drawn (:mod:`hybridgen.scene.room_plan`) and built as the
objects ``Floor``, ``Wall`` and ``Ceiling`` (every surface facing into the room, cube-projected UVs, one texture
repeat per metre); the floor and the walls (the ceiling with ``assign_material_to_ceiling``) get a random
opaque material of the run's library (``loader.CCMaterialLoader``'s, alpha 1, no alpha map); then the loaded
objects, biggest bounding box first, are placed on the floor round robin over the plan's pieces:
``amount_of_objects_per_sq_meter`` sets the floor area per placement, ``placement_tries_per_face`` the tries
per placement. A placement puts the object's origin on the floor (z = 0) at a uniform point of the piece with
a uniform turn about Z (x and y rotation 0, scale kept) and keeps it when it intersects no wall, no ceiling
and no object placed before (exact mesh tests); a placed object is duplicated (sharing its mesh arrays, named
``name.001`` ... as Blender names copies) for the next placement. Loaded objects never placed are removed.

A model the loaders split into several objects (one per material, all with one name) moves as one.
"""
from __future__ import annotations

import copy
from typing import Any

import numpy as np

from ..config.paths import resolve_module_paths
from ..config.schema import Param, positive
from ..config.registry import register_module
from ..errors import ConfigError
from ..io.mesh_loader import unique_blender_name
from ..run.context import RunContext
from ..sampling.room_filling import RoomPlacer, fill_round_robin
from ..scene.mesh_object import MeshObject
from ..scene.room_plan import Rect, random_plan, room_meshes
from .base import Module, Role
from .camera_object_sampler import nested_module
from .material_library import material_library

REPETITIONS = "amount_of_repetitions"


def loader_modules(entries: Any, index: int) -> list[tuple[Module, int]]:
    """The modules of ``used_loader_config`` with their repetition counts (ConfigError naming the entry)."""
    if not isinstance(entries, list):
        raise ConfigError("must be a list of {module: loader.X, config: {...}, amount_of_repetitions: N}")
    out = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            raise ConfigError(f"entry {i} must be a mapping {{module: loader.X, config: {{...}}}}")
        repetitions = entry.get(REPETITIONS, 1)
        if not isinstance(repetitions, int) or isinstance(repetitions, bool) or repetitions < 0:
            raise ConfigError(f"entry {i}: {REPETITIONS} must be an integer >= 0, got {repetitions!r}")
        try:
            module = nested_module({k: v for k, v in entry.items() if k != REPETITIONS}, index)
        except ConfigError as exc:
            raise ConfigError(f"entry {i}: {exc.key + ': ' if exc.key else ''}{exc.detail}") from None
        out.append((module, repetitions))
    return out


def _loaders_problem(value: Any) -> str | None:
    try:
        loader_modules(value, 0)
    except ConfigError as exc:
        return exc.detail
    return None


def _group_models(objects: list[MeshObject]) -> list[list[MeshObject]]:
    """Objects with one name (the parts of one model) as one group, in first-seen order."""
    groups: dict[str, list[MeshObject]] = {}
    for obj in objects:
        groups.setdefault(obj.name, []).append(obj)
    return list(groups.values())


def _bounding_volume(group: list[MeshObject]) -> float:
    corners = np.concatenate([o.world_vertices() for o in group])
    return float(np.prod(corners.max(axis=0) - corners.min(axis=0)))


def _duplicate(group: list[MeshObject]) -> list[MeshObject]:
    """Copies of the parts sharing their mesh arrays and material (the same objects, so renderers draw them as
    instances of one mesh), each with its own pose and attributes."""
    copies = []
    for part in group:
        twin = copy.copy(part)
        twin.attributes = copy.deepcopy(part.attributes)
        twin.local2world = part.local2world.copy()
        copies.append(twin)
    return copies


@register_module("constructor.RandomRoomConstructor")
class RandomRoomConstructor(Module):
    """Builds a random room and places the objects of its loaders in it (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("floor_area", "float", unit="m^2", doc="floor area of the room",
              check=lambda v: None if v > 0 else "must be > 0"),
        Param("used_loader_config", "list", [], check=_loaders_problem,
              doc="loader entries {module, config, amount_of_repetitions} whose objects fill the room"),
        Param("amount_of_extrusions", "int", 0, doc="corridors swept out of the base rectangle (at most)",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("fac_base_from_square_room", "float", 0.3, doc="base side = sqrt(area) * (1 + fac * U(-1, 1))",
              check=lambda v: None if 0 <= v < 1 else "must be in 0..1 (1 excluded)"),
        Param("minimum_corridor_width", "float", 0.9, "m", "only edges longer than this are extruded",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("wall_height", "float", 2.5, "m", check=positive),
        Param("amount_of_floor_cuts", "int", 2, doc="cuts of the base rectangle (more, shorter edges)",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("only_use_big_edges", "bool", True, doc="extrude only from the longer half of the wide edges"),
        Param("create_ceiling", "bool", True, doc="make the Ceiling object"),
        Param("assign_material_to_ceiling", "bool", False, doc="give the ceiling a library material too"),
        Param("placement_tries_per_face", "int", 3, doc="poses tried per placement", check=positive),
        Param("amount_of_objects_per_sq_meter", "float", 3.0, doc="placements per m^2 of floor (approximate)",
              check=positive),
    )

    def __init__(self, config: dict[str, Any], index: int) -> None:
        super().__init__(config, index)
        self.loaders = loader_modules(config["used_loader_config"], index)

    def prepare(self, context: RunContext) -> None:
        for module, _ in self.loaders:
            if context.config is not None:
                resolve_module_paths(module.params, module.config, context.config.path)
            module.prepare(context)

    def run(self, context: RunContext) -> None:
        scene = context.scene
        before = {id(o) for o in scene.objects}
        for module, repetitions in self.loaders:
            for _ in range(repetitions):
                module.run(context)
        loaded = [o for o in scene.objects if id(o) not in before]
        scene.remove(*loaded)
        cfg = self.config
        pieces = random_plan(cfg["floor_area"], cfg["amount_of_extrusions"], cfg["fac_base_from_square_room"],
                             cfg["minimum_corridor_width"], cfg["amount_of_floor_cuts"], cfg["only_use_big_edges"],
                             context.rng)
        floor, walls, ceiling = self._build(context, pieces)
        placer = RoomPlacer([walls] + ([ceiling] if ceiling is not None else []), cfg["placement_tries_per_face"],
                            context.rng)
        models = _group_models(loaded)
        self._fill(context, pieces, models, placer)
        taken = {o.name for o in scene.objects}
        for group in placer.placed:
            name = unique_blender_name(group[0].name, taken)
            taken.add(name)
            for part in group:
                part.name = name
                scene.add(part)
        context.log(f"{self.module_name}: room of {len(pieces)} pieces, {cfg['floor_area']} m^2; placed "
                    f"{len(placer.placed)} object(s) from {len(models)} loaded")

    def _build(self, context: RunContext, pieces: list[Rect]) -> tuple[MeshObject, MeshObject, MeshObject | None]:
        meshes = room_meshes(pieces, self.config["wall_height"])
        floor = MeshObject("Floor", meshes.floor[0], meshes.floor[1], uvs=meshes.floor[2])
        walls = MeshObject("Wall", meshes.walls[0], meshes.walls[1], uvs=meshes.walls[2])
        ceiling = MeshObject("Ceiling", meshes.ceiling[0], meshes.ceiling[1], uvs=meshes.ceiling[2]) \
            if self.config["create_ceiling"] else None
        opaque = [m.material for m in material_library(context)
                  if m.properties.get("is_cc_texture") and m.material.alpha == 1.0 and m.material.alpha_texture is None]
        if opaque:
            targets = [floor, walls] + ([ceiling] if ceiling is not None and
                                        self.config["assign_material_to_ceiling"] else [])
            for obj in targets:
                obj.material = copy.copy(opaque[int(context.rng.integers(len(opaque)))])
        else:
            context.log(f"{self.module_name}: no opaque CC material in the library (run loader.CCMaterialLoader "
                        "before): floor, walls and ceiling keep the default material", "warning")
        taken = {o.name for o in context.scene.objects}
        for obj in (walls, floor, ceiling):
            if obj is not None:
                obj.name = unique_blender_name(obj.name, taken)
                taken.add(obj.name)
                context.scene.add(obj)
        return floor, walls, ceiling

    def _fill(self, context: RunContext, pieces: list[Rect], groups: list[list[MeshObject]],
              placer: RoomPlacer) -> None:
        """BlenderProc's round robin (:func:`hybridgen.sampling.room_filling.fill_round_robin`), biggest model
        first."""
        fill_round_robin(pieces, sorted(groups, key=_bounding_volume, reverse=True),
                         self.config["amount_of_objects_per_sq_meter"], context.rng, placer.try_piece, _duplicate)
