"""What the dataset loaders (ShapeNet, 3D-FRONT, Replica, SceneNet, Pix3D, IKEA) share: their folder and
JSON checks (one line naming the key), BlenderProc's ``add_properties`` and origin moves."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..config.schema import Param
from ..errors import ConfigError
from ..scene.mesh_object import MeshObject

ADD_PROPERTIES = Param("add_properties", "dict", {}, doc="cp_* custom properties of every loaded object "
                       "(cp_category_id sets category_id)")


def dataset_folder(path: Any, key: str, what: str) -> Path:
    """``path`` as an existing folder, else a ConfigError naming ``key``."""
    folder = Path(path)
    if not folder.is_dir():
        raise ConfigError(f"{what} folder not found: '{folder}'", key=key)
    return folder


def dataset_file(path: Path, key: str, what: str) -> Path:
    """``path`` as an existing file, else a ConfigError naming ``key``."""
    if not path.is_file():
        raise ConfigError(f"{what} not found: '{path}'", key=key)
    return path


def read_json(path: Path, key: str, what: str) -> Any:
    """The parsed JSON file ``path``; one line naming the file and ``key`` if missing or broken."""
    dataset_file(path, key, what)
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ConfigError(f"{what} '{path}' is not valid JSON: {exc}", key=key) from None


def add_properties(objects: list[MeshObject], properties: dict[str, Any]) -> None:
    """BlenderProc's loader ``add_properties``: ``cp_category_id`` -> category_id, other ``cp_<name>`` ->
    attribute ``<name>``."""
    for key, value in properties.items():
        if not key.startswith("cp_"):
            raise ConfigError("loaders set only custom properties (cp_* keys), as in BlenderProc",
                              key=f"add_properties.{key}")
        for obj in objects:
            if key == "cp_category_id":
                obj.category_id = int(value)
            else:
                obj.attributes[key[3:]] = value


def move_origin_to_bottom_centre(objects: list[MeshObject]) -> None:
    """Shift the vertices of ``objects`` (parts of one model) so that the origin is the centre of their joint
    bounding box in x and y and its lowest z (BlenderProc's ``move_origin_to_bottom_mean_point``; the pose
    stays, the model moves)."""
    corners = np.concatenate([o.world_vertices() for o in objects])
    low, high = corners.min(axis=0), corners.max(axis=0)
    shift_world = -np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]])
    for obj in objects:
        shift_local = np.linalg.solve(obj.local2world[:3, :3], shift_world)
        obj.vertices = obj.vertices + shift_local
        obj.forget_derived()


def nonnegative(value: Any, key: str) -> float:
    """A number >= 0, else a ConfigError naming ``key``."""
    number = float(value)
    if not np.isfinite(number) or number < 0:
        raise ConfigError(f"must be a finite number >= 0, got {value!r}", key=key)
    return number
