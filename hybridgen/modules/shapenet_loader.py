"""``loader.ShapeNetLoader``: one model of a ShapeNetCore.v2 category, as BlenderProc loads it.

Layout read: ``<data_path>/taxonomy.json`` and ``<data_path>/<synset_id>/<source_id>/models/model_normalized.obj``
(+ its MTL and ``../images`` textures). ``used_synset_id`` may name a child synset of the taxonomy: its
parent chain is followed up to a synset that has a folder (BlenderProc's ``find_parent_synset_id``). Without
``used_source_id`` one model of the synset is drawn (the run's random generator, over the sorted ``*.obj``
files of ``<synset>/*/models/``).

Like BlenderProc: the OBJ is read with Blender's OBJ axes (file +Y -> world +Z, file -Z -> world +Y, the
turn baked into the vertices: the object's rotation stays zero) and, with ``move_object_origin`` (default),
the model is shifted so that its origin is the bottom centre of its bounding box. Objects get the attributes
``used_synset_id`` (as given) and ``used_source_id`` (the model folder); BlenderProc assigns no category_id
(give ``add_properties: {cp_category_id: N}``). A model with several materials becomes one object per
material (same name, attribute ``material_part``), moved together.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.mesh_cache import load_objects_cached
from ..run.context import RunContext
from .base import Module, Role
from .dataset_support import (ADD_PROPERTIES, add_properties, dataset_folder, move_origin_to_bottom_centre,
                              read_json)
from .obj_loader import add_with_blender_names


def parent_synset(data_path: Path, synset_id: str, taxonomy: list[dict[str, Any]]) -> str:
    """``synset_id`` if it has a folder, else its nearest ancestor in ``taxonomy`` that has one."""
    seen = set()
    current = synset_id
    while not (data_path / current).is_dir():
        seen.add(current)
        parents = [b.get("synsetId") for b in taxonomy if isinstance(b, dict) and current in b.get("children", [])]
        if not parents or parents[0] in seen:
            raise ConfigError(f"synset '{synset_id}' has no folder in '{data_path}' and no parent in taxonomy.json "
                              "that has one", key="used_synset_id")
        current = str(parents[0])
    return current


def shapenet_models(data_path: Path, synset_id: str, source_id: str) -> list[Path]:
    """The sorted OBJ files of ``synset_id`` (of model ``source_id`` only if given)."""
    taxonomy = read_json(data_path / "taxonomy.json", "data_path", "ShapeNet taxonomy file")
    if not isinstance(taxonomy, list):
        raise ConfigError(f"'{data_path / 'taxonomy.json'}' must hold a list of synsets", key="data_path")
    folder = data_path / parent_synset(data_path, synset_id, taxonomy)
    if source_id:
        if not (folder / source_id).is_dir():
            raise ConfigError(f"no model '{source_id}' in '{folder}'", key="used_source_id")
        files = sorted((folder / source_id / "models").glob("*.obj"))
    else:
        files = sorted(folder.glob("*/models/*.obj"))
    if not files:
        raise ConfigError(f"no <source_id>/models/*.obj under '{folder}'",
                          key="used_source_id" if source_id else "used_synset_id")
    return files


@register_module("loader.ShapeNetLoader")
class ShapeNetLoader(Module):
    """Loads one ShapeNetCore.v2 model of a synset (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("data_path", "path", doc="the ShapeNetCore.v2 folder (holding taxonomy.json)"),
        Param("used_synset_id", "str", doc="category synset id, e.g. '02691156' (airplane)"),
        Param("used_source_id", "str", "", doc="one model's folder name (default: a random model of the synset)"),
        Param("move_object_origin", "bool", True, doc="origin to the bottom centre of the model's bounding box"),
        ADD_PROPERTIES,
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        data_path = dataset_folder(cfg["data_path"], "data_path", "ShapeNet")
        synset = str(cfg["used_synset_id"])
        files = shapenet_models(data_path, synset, str(cfg["used_source_id"]))
        chosen = files[int(context.rng.integers(len(files)))] if len(files) > 1 else files[0]
        objects = load_objects_cached(chosen, up_axis="Y", attributes={
            "used_synset_id": synset, "used_source_id": chosen.parent.parent.name},
            notify=lambda line: notice(line, module=self.module_name, index=self.index))
        if cfg["move_object_origin"]:
            move_origin_to_bottom_centre(objects)
        add_properties(objects, cfg["add_properties"])
        add_with_blender_names(context, objects, renamed=True)
