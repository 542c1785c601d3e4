"""A 3D-FRONT house JSON read into scene objects, the way BlenderProc 1.12's Front3DLoader builds them.

- ``mesh`` entries (walls, floors, ceilings ...): ``xyz``/``normal`` (flat lists, 3D-FRONT's y up, swapped
  to z up by exchanging y and z as BlenderProc does), ``uv`` (None entries dropped), ``faces`` (flat vertex
  indices), ``material`` (uid into ``material``). Name = ``type`` (``void`` when empty); entries without a
  material are skipped with a notice. A material with a ``texture`` URL reads
  ``<texture_path>/<hash>/texture.png`` (``hash`` = the URL's last folder; BlenderProc would download a
  missing one, hybridgen names it), ``normaltexture`` likewise as an OpenGL normal map, ``color`` (0..255)
  as base color. Ceilings emit their color with ``ceiling_light_strength``.
- ``furniture`` entries: ``<future_path>/<jid>/raw_model.obj`` with ``texture.png`` of the same folder as the
  base color of every part; name = ``category``, else ``title`` up to its first ``/``, else ``others``. Beds
  and sofas get roughness 0.5, lamps emit their texture (per texel) with ``lamp_light_strength``. A missing
  model is skipped, as BlenderProc does (a notice counts them). Each model file is parsed once; every
  placement shares its vertex arrays.
- ``scene.room[i].children`` with ``furniture`` in ``instanceid`` place the furniture of ``uid == ref``:
  location = ``pos`` (x, z, y), rotation = Rx(-90 deg) x the quaternion ``rot`` read as Blender's
  ``Quaternion(rot)`` (w first), scale = ``scale``, applied to the OBJ's coordinates as stored (this pose
  replaces the axis turn Blender's OBJ import puts on the object); attribute ``room_id`` = i.

Every object gets ``is_3d_front: true`` and ``category_id`` = the label mapping's id of its lower-cased name.
Emissive ceilings and lamps show their principled surface to camera rays and emit only for other rays, as
BlenderProc's (``emission_hidden_from_camera``, :mod:`hybridgen.render.pathtrace.camera_hidden_emission`; in JIT Mitsuba
variants - ``scalar_rgb`` shows them glowing, with a notice).
"""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import ConfigError
from ..scene.material import Material
from ..scene.mesh_object import MeshObject

FURNITURE_FILE = "raw_model.obj"
TEXTURE_FILE = "texture.png"


def label_mapping(path: Path) -> dict[str, int]:
    """BlenderProc's label mapping CSV (columns ``id``, ``name``) as name -> id."""
    if not path.is_file():
        raise ConfigError(f"label mapping CSV not found: '{path}' (BlenderProc ships 3D-FRONT's as "
                          "resources/front_3D/3D_front_mapping.csv)", key="mapping_file")
    mapping: dict[str, int] = {}
    with open(path, newline="", encoding="utf-8") as handle:
        reader = csv.DictReader(handle)
        if reader.fieldnames is None or not {"id", "name"} <= set(reader.fieldnames):
            raise ConfigError(f"'{path}' needs the columns id and name", key="mapping_file")
        for row in reader:
            try:
                mapping[row["name"]] = int(row["id"])
            except (TypeError, ValueError):
                raise ConfigError(f"'{path}' line {reader.line_num}: id {row['id']!r} is not an integer",
                                  key="mapping_file") from None
    return mapping


def category_of(mapping: dict[str, int], name: str, mapping_path: Path) -> int:
    """The id of ``name`` (lower-cased) in ``mapping``; one line naming the label and the file otherwise."""
    label = name.lower()
    if label not in mapping:
        raise ConfigError(f"label '{label}' is not in the label mapping '{mapping_path}'", key="mapping_file")
    return mapping[label]


def _texture_in(folder: Path, what: str) -> str:
    path = folder / TEXTURE_FILE
    if not path.is_file():
        raise ConfigError(f"{what} not found: '{path}'", key="3D_front_texture_path")
    return str(path)


def _hash_folder(url: str, texture_path: Path) -> Path:
    return texture_path / url.rstrip("/").split("/")[-2]


def _floats(values: Any, key: str, owner: str, json_path: Path) -> np.ndarray:
    try:
        return np.asarray([float(v) for v in values if v is not None], dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"'{json_path}': mesh '{owner}' has a non-numeric '{key}'", key="json_path") from None


def house_meshes(data: dict[str, Any], json_path: Path, texture_path: Path, ceiling_strength: float,
                 category: Callable[[str], int], notify: Callable[[str], None]) -> list[MeshObject]:
    """The objects of the JSON's ``mesh`` array (see the module doc)."""
    materials = {m.get("uid"): m for m in data.get("material", []) if isinstance(m, dict)}
    objects, skipped = [], 0
    for entry in data.get("mesh", []):
        name = str(entry.get("type", "")).strip() or "void"
        if "material" not in entry:
            skipped += 1
            continue
        xyz = _floats(entry.get("xyz", []), "xyz", name, json_path).reshape(-1, 3)
        normals = _floats(entry.get("normal", []), "normal", name, json_path).reshape(-1, 3)
        xyz[:, [1, 2]] = xyz[:, [2, 1]]
        normals[:, [1, 2]] = normals[:, [2, 1]]
        uv = _floats(entry.get("uv", []), "uv", name, json_path)
        material = _mesh_material(materials.get(entry["material"]), name, texture_path, ceiling_strength)
        obj = MeshObject(name, xyz, np.asarray(entry.get("faces", []), dtype=np.int64).reshape(-1, 3),
                         vertex_normals=normals if len(normals) == len(xyz) else None,
                         uvs=uv.reshape(-1, 2) if len(uv) == 2 * len(xyz) else None, material=material,
                         category_id=category(name), attributes={"is_3D_future": True, "uid": str(entry.get("uid", ""))})
        objects.append(obj)
    if skipped:
        notify(f"'{json_path}': {skipped} mesh entr{'y' if skipped == 1 else 'ies'} without a material skipped "
               "(as BlenderProc)")
    return objects


def _mesh_material(entry: dict[str, Any] | None, name: str, texture_path: Path, ceiling_strength: float) -> Material:
    material = Material(name=f"{name}_material")
    if entry is None:
        return material
    color = entry.get("color")
    if isinstance(color, list) and len(color) >= 3:
        rgba = [float(c) / 255.0 for c in color[:4]] + [1.0] * (4 - min(len(color), 4))
        material.base_color = tuple(min(max(c, 0.0), 1.0) for c in rgba)  # type: ignore[assignment]
    if entry.get("texture"):
        material.base_color_texture = _texture_in(_hash_folder(entry["texture"], texture_path), "3D-FRONT texture")
    if entry.get("normaltexture"):
        material.normal_texture = _texture_in(_hash_folder(entry["normaltexture"], texture_path),
                                              "3D-FRONT normal texture")
    if "ceiling" in name.lower():
        material.emission = tuple(material.base_color[:3])  # type: ignore[assignment]
        material.emission_strength = float(ceiling_strength)
        material.emission_hidden_from_camera = True  # as BlenderProc's make_emissive: the camera sees the ceiling
    return material


def furniture_pose(child: dict[str, Any]) -> np.ndarray:
    """local2world of a room child: T(pos x, z, y) . Rx(-90 deg) . R(quaternion rot, w first) . S(scale)."""
    w, x, y, z = (float(v) for v in child.get("rot", [1.0, 0.0, 0.0, 0.0]))
    norm = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    to_z_up = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])  # Rx(-90 deg)
    pos = [float(v) for v in child.get("pos", [0.0, 0.0, 0.0])]
    scale = [float(v) for v in child.get("scale", [1.0, 1.0, 1.0])]
    pose = np.eye(4)
    pose[:3, :3] = to_z_up @ rotation @ np.diag(scale)
    pose[:3, 3] = [pos[0], pos[2], pos[1]]
    return pose


def furniture_name(entry: dict[str, Any]) -> str:
    """BlenderProc's name of a furniture entry: category, else title up to '/', else 'others'."""
    name = entry.get("category") or str(entry.get("title") or "").split("/")[0]
    return str(name) or "others"


def mean_linear_color(path: str) -> tuple[float, float, float]:
    """Mean linear RGB of an sRGB image (a lamp's emission color)."""
    from PIL import Image

    with Image.open(path) as image:
        values = np.asarray(image.convert("RGB"), dtype=np.float64) / 255.0
    linear = np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)
    return tuple(float(c) for c in linear.reshape(-1, 3).mean(axis=0))  # type: ignore[return-value]


def placed_copy(model: MeshObject, pose: np.ndarray, attributes: dict[str, Any]) -> MeshObject:
    """Another placement of ``model`` sharing its vertex, face, normal and UV arrays (no copies)."""
    copy = MeshObject.__new__(MeshObject)
    copy.__dict__.update(model.__dict__)
    copy.attributes = {**model.attributes, **attributes}
    copy.local2world = pose @ model.local2world
    copy.instance_id = 0
    return copy
