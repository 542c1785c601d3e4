"""Materials a run keeps without an object: the library ``loader.CCMaterialLoader`` fills and
``manipulators.MaterialRandomizer`` draws from (BlenderProc's materials that exist before they are used).

``loader.CCMaterialLoader`` reads a cc0textures-style folder: one sub-folder per asset holding
``<asset>_2K_Color.jpg`` (or any ``*_Color.*`` / ``*_col.*`` image). Each asset becomes a principled material
named after the folder, its color image as ``base_color_texture``, kept with the custom properties
``is_cc_texture: true`` and ``asset_path`` that getter.Material conditions (``cp_is_cc_texture``) select by.
Roughness, normal and displacement maps are not used by hybridgen's principled material (one notice).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import InputError
from ..run.context import RunContext
from ..scene.material import Material
from .base import Module, Role

_COLOR_FILE = re.compile(r".*_(2K_)?(Color|col|diffuse|albedo)\.(jpg|jpeg|png)$", re.IGNORECASE)


@dataclass
class LibraryMaterial:
    """A material of the library with its custom properties (BlenderProc's ``cp_*`` of a material)."""

    material: Material
    properties: dict[str, Any] = field(default_factory=dict)


def material_library(context: RunContext) -> list[LibraryMaterial]:
    """The run's library of loaded, not yet used materials (created empty on first use)."""
    library = context.__dict__.get("material_library")
    if library is None:
        library = context.__dict__["material_library"] = []
    return library


def material_matches(entry: LibraryMaterial, conditions: Any) -> bool:
    """BlenderProc getter.Material conditions on a material: ``name`` (regular expression) and ``cp_<key>``
    (its properties); a list is an OR of mappings."""
    if conditions is None:
        return True
    if isinstance(conditions, list):
        return any(material_matches(entry, c) for c in conditions)
    for key, wanted in conditions.items():
        if key == "name":
            if re.fullmatch(str(wanted), entry.material.name) is None:
                return False
            continue
        actual = entry.properties.get(key[3:] if key.startswith("cp_") else key)
        if actual != wanted:
            return False
    return True


def cc_materials(folder: Path, used_assets: list[str]) -> list[LibraryMaterial]:
    """One material per asset folder of ``folder`` whose name starts with one of ``used_assets`` (all if empty)."""
    if not folder.is_dir():
        raise InputError(f"cc texture folder not found: '{folder}'")
    materials = []
    for asset in sorted(p for p in folder.iterdir() if p.is_dir()):
        if used_assets and not any(asset.name.startswith(prefix) for prefix in used_assets):
            continue
        colors = sorted(p for p in asset.iterdir() if _COLOR_FILE.match(p.name))
        if not colors:
            continue
        materials.append(LibraryMaterial(Material(name=asset.name, base_color_texture=str(colors[0])),
                                         {"is_cc_texture": True, "asset_path": str(asset)}))
    return materials


@register_module("loader.CCMaterialLoader")
class CCMaterialLoader(Module):
    """Loads cc0textures assets as materials into the run's material library (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("folder_path", "path", doc="folder with one sub-folder per texture asset"),
        Param("used_assets", "list", [], doc="only assets whose names start with one of these"),
        Param("preload", "bool", False, doc="BlenderProc's lazy loading switch; hybridgen reads images when "
              "rendering either way"),
        Param("fill_used_empty_materials", "bool", False, doc="BlenderProc's two-phase loading switch; hybridgen "
              "loads everything at once"),
        Param("add_custom_properties", "dict", {}, doc="extra properties of every loaded material (cp_* keys)"),
    )

    def run(self, context: RunContext) -> None:
        materials = cc_materials(Path(self.config["folder_path"]), [str(a) for a in self.config["used_assets"]])
        if not materials:
            raise InputError(f"no texture asset (<asset>/<asset>_2K_Color.jpg) in '{self.config['folder_path']}'")
        for entry in materials:
            for key, value in self.config["add_custom_properties"].items():
                entry.properties[key[3:] if key.startswith("cp_") else key] = value
        notice("only the color image of each asset is used (hybridgen's principled material has no roughness, "
               "normal or displacement maps)", module=self.module_name, index=self.index, key="folder_path")
        material_library(context).extend(materials)
