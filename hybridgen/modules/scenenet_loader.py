"""``loader.SceneNetLoader``: a SceneNet room (one ``.obj`` of many named objects) as BlenderProc loads it.

- The OBJ is read with Blender's OBJ axes; objects are sorted by name.
- Every object's material gets a base-color texture drawn (run's random generator, sorted files) from
  ``<texture_folder>/<name>/*``, ``name`` being the material's name up to its first ``.``, without ``_`` and
  digits; from ``unknown_texture_folder`` (default ``<texture_folder>/unknown``) when there is no such folder.
- Walls, floors and ceilings are flat shaded (their vertex normals dropped), as BlenderProc sets them.
- ``category_id`` from the NYU label mapping CSV (``id,name``; BlenderProc ships it as
  ``resources/id_mappings/nyu_idset.csv``): the object's lower-cased name up to its first ``.``, after
  SceneNet's naming quirks are normalised (``ground`` -> floor, ``room_skeleton`` -> wall, ``nightstand`` ->
  night_stand ...), else that name without its last character (plurals), else ``picture`` for paintings,
  else ``otherstructure``. Objects labelled floor / ceiling are renamed so. Attribute ``is_scene_net_obj``.
"""
from __future__ import annotations

from pathlib import Path

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.front3d_house import label_mapping
from ..io.mesh_cache import load_objects_cached
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from .base import Module, Role
from .dataset_support import ADD_PROPERTIES, add_properties, dataset_file, dataset_folder
from .obj_loader import add_with_blender_names

SCENENET_NAMES = {
    "floor-mat": "floor_mat", "refrigerator": "refridgerator", "shower-curtain": "shower_curtain",
    "nightstand": "night_stand", "other-structure": "otherstructure", "other-furniture": "otherfurniture",
    "other-prop": "otherprop", "floor_tiles_floor_tiles_0125": "floor", "ground": "floor", "floor_enclose": "floor",
    "floor_enclose2": "floor", "floor_base_object01_56": "floor", "walls1_line01_12": "wall",
    "room_skeleton": "wall", "ceilingwall": "ceiling",
}
"""SceneNet object names that differ from their NYU label (lower-cased)."""


def nyu_label(name: str, mapping: dict[str, int]) -> str:
    """The NYU label of a SceneNet object name (see the module doc)."""
    base = name.lower().split(".")[0]
    base = SCENENET_NAMES.get(base, base)
    if base in mapping:
        return base
    if base[:-1] in mapping:
        return base[:-1]
    return "picture" if "painting" in base else "otherstructure"


def texture_key(material_name: str) -> str:
    """The texture folder name of a material: up to the first '.', without '_' and digits."""
    return "".join(c for c in material_name.split(".")[0].replace("_", "") if not c.isdigit())


@register_module("loader.SceneNetLoader")
class SceneNetLoader(Module):
    """Loads a SceneNet room with sampled textures and NYU categories (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("file_path", "path", doc="the room's .obj file"),
        Param("texture_folder", "path", doc="SceneNet texture folder (one sub-folder per material name)"),
        Param("unknown_texture_folder", "path|null", None, doc="textures for names without a folder "
              "(default <texture_folder>/unknown)"),
        Param("mapping_file", "path", "resources/id_mappings/nyu_idset.csv", doc="NYU label mapping CSV (id,name)"),
        ADD_PROPERTIES,
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        path = dataset_file(Path(cfg["file_path"]), "file_path", "SceneNet room file")
        textures = dataset_folder(cfg["texture_folder"], "texture_folder", "SceneNet texture")
        unknown = Path(cfg["unknown_texture_folder"] or textures / "unknown")
        mapping = label_mapping(Path(cfg["mapping_file"]))
        for label in ("otherstructure", "picture", "floor", "ceiling"):
            if label not in mapping:
                raise ConfigError(f"the NYU mapping '{cfg['mapping_file']}' lacks '{label}'", key="mapping_file")
        objects = sorted(load_objects_cached(path, up_axis="Y", notify=lambda line: notice(
            line, module=self.module_name, index=self.index)), key=lambda o: o.name)
        for obj in objects:
            self._texture(context, obj, textures, unknown)
            if any(word in obj.name.lower().split(".")[0] for word in ("wall", "floor", "ceiling")):
                obj.vertex_normals = None
            obj.category_id = mapping[nyu_label(obj.name, mapping)]
            if obj.category_id == mapping["floor"]:
                obj.name = "floor"
            elif obj.category_id == mapping["ceiling"]:
                obj.name = "ceiling"
            obj.attributes["is_scene_net_obj"] = True
        add_properties(objects, cfg["add_properties"])
        add_with_blender_names(context, objects, renamed=True)

    @staticmethod
    def _texture(context: RunContext, obj: MeshObject, textures: Path, unknown: Path) -> None:
        folder = textures / texture_key(obj.material.name)
        images = sorted(p for p in folder.glob("*") if p.is_file()) if folder.is_dir() else []
        if not images:
            if not unknown.is_dir():
                raise ConfigError(f"no texture folder '{folder.name}' and the unknown texture folder '{unknown}' "
                                  "does not exist", key="unknown_texture_folder")
            images = sorted(p for p in unknown.glob("*") if p.is_file())
            if not images:
                raise ConfigError(f"the unknown texture folder '{unknown}' holds no texture",
                                  key="unknown_texture_folder")
        obj.material.base_color_texture = str(images[int(context.rng.integers(len(images)))])
