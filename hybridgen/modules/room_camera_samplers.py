"""``camera.Front3DCameraSampler`` and ``camera.ReplicaCameraSampler``: BlenderProc's camera samplers for indoor
datasets - ``camera.CameraSampler`` (every key and check of it), except that each candidate's place is drawn
inside a room (:mod:`hybridgen.sampling.room_points`):

- the entry's ``location`` (sampled as usual) gives only the height: its z is the camera's height above the
  room's floor (3D-FRONT: the floor object's origin; Replica: one of the scene's floor heights); x and y are
  drawn uniformly in the room's bounding box until the camera stands straight above the room's floor (a ray
  cast down hits that floor first);
- the rotation is the entry's, unchanged (a ``look_at`` rotation looks from the sampled location, as in
  BlenderProc, which also replaces the location after computing the rotation).

3D-FRONT rooms with at most ``amount_of_objects_needed_per_room`` objects on their floor get no camera
(BlenderProc's documented key; its 1.12 code reads the default 2 only). Replica needs the scene's mesh object
(``mesh``, loader.ReplicaLoader) and its floor split off by ``object.FloorExtractor`` (named ``floor``), and a
height list file: ``height_list_path``, or with ``is_replica_object: true`` BlenderProc's
``resources/replica/height_levels/<data_set_name>/height_list_values.txt`` (found from the working directory,
as BlenderProc runs from its checkout, else from the config's folder).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..input_paths import resolve_input
from ..run.context import RunContext
from ..sampling.room_points import Front3DRoomPoints, ReplicaRoomPoints, read_height_list
from ..scene.mesh_object import MeshObject
from .camera_sampler import CameraSampler

REPLICA_HEIGHT_LEVELS = "resources/replica/height_levels"
"""Where BlenderProc 1.12 keeps each Replica scene's floor heights (``<scene>/height_list_values.txt``)."""


def _nonnegative_int(value: int) -> str | None:
    return None if value >= 0 else "must be >= 0"


@register_module("camera.Front3DCameraSampler")
class Front3DCameraSampler(CameraSampler):
    """camera.CameraSampler with every camera inside a furnished room of a loaded 3D-FRONT house."""

    params = CameraSampler.params + (
        Param("amount_of_objects_needed_per_room", "int", 2, doc="a room gets cameras when more than this many "
              "3D-FRONT objects (walls and ceilings not counted) stand on its floor", check=_nonnegative_int),
    )

    def _prepare_sampling(self, context: RunContext) -> None:
        self._rooms = Front3DRoomPoints(context.scene.objects, self.config["amount_of_objects_needed_per_room"])
        counts = ", ".join(f"{name} {count}" for name, count in self._rooms.counts)
        context.log(f"{self.module_name}: {len(self._rooms.floors)} of {len(self._rooms.counts)} rooms used "
                    f"(objects per floor: {counts})")

    def _relocate(self, cam2world: np.ndarray, context: RunContext) -> np.ndarray:
        pose = cam2world.copy()
        pose[:3, 3], _ = self._rooms.sample(float(cam2world[2, 3]), context.rng)
        return pose


@register_module("camera.ReplicaCameraSampler")
class ReplicaCameraSampler(CameraSampler):
    """camera.CameraSampler with every camera above the extracted floor of a loaded Replica scene."""

    params = CameraSampler.params + (
        Param("is_replica_object", "bool", False, doc="read the height list of data_set_name from BlenderProc's "
              f"{REPLICA_HEIGHT_LEVELS}/<data_set_name>/height_list_values.txt"),
        Param("height_list_path", "path|null", None, doc="file listing the scene's floor heights [m], e.g. "
              "[-1.54, 1.309] (when is_replica_object is false)"),
        Param("data_set_name", "str|null", None, doc="the Replica scene (e.g. office_1), for is_replica_object"),
        Param("mesh_name", "str", "mesh", doc="the scene mesh's object (loader.ReplicaLoader names it mesh)"),
        Param("floor_name", "str", "floor", doc="the floor object (object.FloorExtractor's name_for_split_obj)"),
        Param("height_levels", "path", REPLICA_HEIGHT_LEVELS, doc="folder of <data_set_name>/height_list_values.txt "
              "for is_replica_object (BlenderProc 1.0: resources/replica-dataset/height_levels)"),
    )

    def _height_list(self) -> Path:
        cfg = self.config
        if not cfg["is_replica_object"]:
            if cfg["height_list_path"] is None:
                raise ConfigError("give the scene's height list file (or is_replica_object: true with "
                                  "data_set_name)", key="height_list_path")
            return Path(cfg["height_list_path"])
        if not cfg["data_set_name"]:
            raise ConfigError("is_replica_object needs the Replica scene's name (e.g. office_1)",
                              key="data_set_name")
        relative = f"{cfg['height_levels']}/{cfg['data_set_name']}/height_list_values.txt"
        return Path(resolve_input(relative, "data_set_name", noun="Replica height list (from a BlenderProc "
                                                                  "checkout's resources/)"))

    def _named(self, context: RunContext, key: str, what: str) -> MeshObject:
        name = self.config[key]
        for obj in context.scene.objects:
            if obj.name == name:
                return obj
        raise ConfigError(f"the scene has no object named '{name}' ({what})", key=key)

    def _prepare_sampling(self, context: RunContext) -> None:
        heights = read_height_list(self._height_list(), "height_list_path")
        mesh = self._named(context, "mesh_name", "the Replica scene mesh: load it with loader.ReplicaLoader")
        floor = self._named(context, "floor_name", "split the floor off with object.FloorExtractor")
        self._rooms = ReplicaRoomPoints(context.scene.objects, mesh, floor, heights)

    def _relocate(self, cam2world: np.ndarray, context: RunContext) -> np.ndarray:
        pose = cam2world.copy()
        pose[:3, 3] = self._rooms.sample(float(cam2world[2, 3]), context.rng)
        return pose
