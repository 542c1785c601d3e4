"""Single-model dataset loaders as BlenderProc runs them: ``loader.ReplicaLoader``, ``loader.Pix3DLoader`` and
``loader.IKEALoader``.

- Replica: ``<data_path>/<data_set_name>/mesh.ply`` (vertex colors become the per-vertex base color), read
  as stored (z up). ``use_smooth_shading`` is Blender's shading switch: hybridgen shades with the file's
  own normals either way (a notice when it is set).
- Pix3D: ``<data_path>/pix3d.json`` (a list of annotations with ``category`` and ``model``, a path relative to
  ``data_path``); one model of ``used_category`` is drawn from the sorted distinct models, read with
  Blender's OBJ axes, its origin moved to the bottom centre of its bounding box. (BlenderProc caches the
  list in ``category_<name>_paths.txt`` next to the JSON; hybridgen writes nothing into the dataset.)
- IKEA: ``<data_dir>/IKEA/IKEA_<type>_<style>/*.obj`` with a sibling ``.mtl`` of the same stem; ``category``
  (a string or a list) keeps folders whose name contains it, ``style`` folders whose lower-cased name contains
  it (with both: either match, else a random model with a notice, as BlenderProc). Without either, a folder
  then a model in it are drawn; with them, the first model of each matching folder. Objects are named
  after the ``IKEA_*`` folder; the unit in the file's first five lines (``File units: inches``, centimeters,
  millimeters, meters) scales the model to metres; the origin goes to the bottom centre.

Draws use the run's random generator (BlenderProc: Python's ``random``). A model with several materials
becomes one object per material, moved together.
"""
from __future__ import annotations

from pathlib import Path

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.mesh_cache import load_objects_cached
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from .base import Module, Role
from .dataset_support import (ADD_PROPERTIES, add_properties, dataset_file, dataset_folder,
                              move_origin_to_bottom_centre, read_json)
from .obj_loader import add_with_blender_names

IKEA_UNITS = {"inches": 0.0254, "centimeters": 0.01, "millimeters": 0.001, "meters": 1.0}


class _ModelLoader(Module):
    """A loader that adds the parts of one model file with BlenderProc's ``add_properties``."""

    role = Role.LOADER

    def _add(self, context: RunContext, objects: list[MeshObject]) -> None:
        add_properties(objects, self.config["add_properties"])
        add_with_blender_names(context, objects, renamed=True)

    def _load(self, path: Path, up_axis: str) -> list[MeshObject]:
        return load_objects_cached(path, up_axis=up_axis,
                                   notify=lambda line: notice(line, module=self.module_name, index=self.index))


@register_module("loader.ReplicaLoader")
class ReplicaLoader(_ModelLoader):
    """Loads one Replica scene's ``mesh.ply`` (see the module doc)."""

    params = (
        Param("data_path", "path", doc="the Replica folder holding one sub-folder per scene"),
        Param("data_set_name", "str", doc="the scene's folder, e.g. office_1"),
        Param("use_smooth_shading", "bool", False, doc="Blender's shading switch (hybridgen uses the file's "
              "normals)"),
        ADD_PROPERTIES,
    )

    def run(self, context: RunContext) -> None:
        root = dataset_folder(self.config["data_path"], "data_path", "Replica")
        path = dataset_file(root / str(self.config["data_set_name"]) / "mesh.ply", "data_set_name", "Replica mesh")
        if self.config["use_smooth_shading"]:
            notice("use_smooth_shading: hybridgen shades with the mesh's own vertex normals (smooth when the PLY "
                   "has them)", module=self.module_name, index=self.index, key="use_smooth_shading")
        self._add(context, self._load(path, "Z"))


def pix3d_models(data_path: Path, category: str) -> list[Path]:
    """The sorted distinct model files of ``category`` in ``pix3d.json``."""
    annotations = read_json(data_path / "pix3d.json", "data_path", "Pix3D annotation file")
    if not isinstance(annotations, list):
        raise ConfigError(f"'{data_path / 'pix3d.json'}' must hold a list of annotations", key="data_path")
    models = sorted({str(a["model"]) for a in annotations
                     if isinstance(a, dict) and a.get("category") == category and "model" in a})
    if not models:
        known = sorted({str(a.get("category")) for a in annotations if isinstance(a, dict) and "category" in a})
        raise ConfigError(f"no model of category '{category}' in pix3d.json (categories: {', '.join(known)})",
                          key="used_category")
    return [data_path / model for model in models]


@register_module("loader.Pix3DLoader")
class Pix3DLoader(_ModelLoader):
    """Loads one Pix3D model of a category (see the module doc)."""

    params = (
        Param("used_category", "str", doc="bed, bookcase, chair, desk, misc, sofa, table, tool or wardrobe"),
        Param("data_path", "path", "resources/pix3d", doc="the Pix3D folder holding pix3d.json"),
        ADD_PROPERTIES,
    )

    def run(self, context: RunContext) -> None:
        root = dataset_folder(self.config["data_path"], "data_path", "Pix3D")
        models = pix3d_models(root, str(self.config["used_category"]))
        chosen = models[int(context.rng.integers(len(models)))]
        objects = self._load(dataset_file(chosen, "used_category", "Pix3D model"), "Y")
        move_origin_to_bottom_centre(objects)
        self._add(context, objects)


def ikea_models(data_dir: Path) -> dict[str, list[Path]]:
    """``IKEA_*`` folder name -> its ``.obj`` files that have a ``.mtl`` of the same stem (sorted)."""
    found: dict[str, list[Path]] = {}
    for path in sorted((data_dir / "IKEA").glob("*/*.obj")):
        if path.with_suffix(".mtl").is_file() and path.parent.name.startswith("IKEA_"):
            found.setdefault(path.parent.name, []).append(path)
    if not found:
        raise ConfigError(f"no IKEA/IKEA_*/<model>.obj with its .mtl under '{data_dir}'", key="data_dir")
    return found


def ikea_unit_scale(path: Path) -> float:
    """Metres per file unit from the ``File units`` line among the first five (1 without one)."""
    with open(path, encoding="utf-8", errors="replace") as handle:
        head = [handle.readline() for _ in range(5)]
    for line in head:
        if "File units" in line:
            unit = line.strip().split(" ")[-1]
            if unit not in IKEA_UNITS:
                raise ConfigError(f"'{path}': unknown file unit '{unit}' (known: {', '.join(IKEA_UNITS)})",
                                  key="data_dir")
            return IKEA_UNITS[unit]
    return 1.0


@register_module("loader.IKEALoader")
class IKEALoader(_ModelLoader):
    """Loads one IKEA model by type and/or style (see the module doc)."""

    params = (
        Param("data_dir", "path", "resources/IKEA", doc="folder holding IKEA/IKEA_<type>_<style>/"),
        Param("category", "str|list|null", None, doc="object type(s), e.g. chair or [bed, sofa]"),
        Param("style", "str|null", None, doc="IKEA product series, e.g. poang"),
        ADD_PROPERTIES,
    )

    def _pick(self, context: RunContext, found: dict[str, list[Path]]) -> Path:
        rng = context.rng
        categories = self.config["category"]
        categories = [categories] if isinstance(categories, str) else categories
        style = self.config["style"]
        keys = list(found)
        if categories is None and style is None:
            folder = found[keys[int(rng.integers(len(keys)))]]
            return folder[int(rng.integers(len(folder)))]
        candidates = [found[k][0] for k in keys
                      if (categories is None or any(str(c) in k for c in categories))
                      and (style is None or str(style) in k.lower())]
        if not candidates:
            notice(f"no IKEA model of category {categories} and style {style!r}: a random model is used",
                   module=self.module_name, index=self.index, key="category")
            folder = found[keys[int(rng.integers(len(keys)))]]
            return folder[int(rng.integers(len(folder)))]
        return candidates[int(rng.integers(len(candidates)))]

    def run(self, context: RunContext) -> None:
        data_dir = dataset_folder(self.config["data_dir"], "data_dir", "IKEA")
        chosen = self._pick(context, ikea_models(data_dir))
        objects = self._load(chosen, "Y")
        scale = ikea_unit_scale(chosen)
        for obj in objects:
            obj.name = chosen.parent.name
            if scale != 1.0:
                obj.vertices = obj.vertices * scale
                obj.forget_derived()
        move_origin_to_bottom_centre(objects)
        self._add(context, objects)
