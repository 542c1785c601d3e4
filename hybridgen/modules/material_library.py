"""Materials a run keeps without an object: the library ``loader.CCMaterialLoader`` fills and
``manipulators.MaterialRandomizer`` draws from (BlenderProc's materials that exist before they are used).

``loader.CCMaterialLoader`` reads an ambientCG (cc0textures) folder: one sub-folder per asset holding
``<asset>_2K_Color.jpg`` and its PBR maps (roughness, metalness, opacity, normal, displacement - see
:mod:`hybridgen.io.texture_sets` for the names). Each asset becomes a principled material named after the
folder, kept with the custom properties ``is_cc_texture: true``, ``asset_name`` (the folder's name, as
BlenderProc names it) and ``asset_path`` that getter.Material conditions (``cp_is_cc_texture``,
``cp_asset_name: "Marble.*"`` - text values are regular expressions the whole value must match) select by.
``loader.HavenMaterialLoader`` (:mod:`hybridgen.modules.haven_loaders`) fills the same library from Poly Haven
folders.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, ClassVar

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.texture_sets import cc_material
from ..run.context import RunContext
from ..scene.material import Material
from .base import Module, Role

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
        if isinstance(actual, str) and isinstance(wanted, str):  # BlenderProc: a regular expression, whole value
            if re.fullmatch(wanted, actual) is None:
                return False
        elif actual != wanted:
            return False
    return True


def asset_materials(folder: Path, used_assets: list[str], read: Callable[[Path], Material | None],
                    properties: dict[str, Any]) -> list[LibraryMaterial]:
    """One material per asset sub-folder of ``folder`` that ``read`` understands, keeping only assets whose
    names start with one of ``used_assets`` (all if empty; compared as BlenderProc does: case and spaces
    ignored)."""
    if not folder.is_dir():
        raise ConfigError(f"texture folder not found: '{folder}'", key="folder_path")
    wanted = [a.lower().replace(" ", "") for a in used_assets]
    materials = []
    for asset in sorted(p for p in folder.iterdir() if p.is_dir()):
        if wanted and not any(asset.name.lower().startswith(prefix) for prefix in wanted):
            continue
        material = read(asset)
        if material is not None:
            materials.append(LibraryMaterial(material, {**properties, "asset_name": asset.name,
                                                        "asset_path": str(asset)}))
    return materials


def cc_materials(folder: Path, used_assets: list[str]) -> list[LibraryMaterial]:
    """One material per ambientCG asset folder of ``folder`` (see :func:`asset_materials`)."""
    return asset_materials(folder, used_assets, cc_material, {"is_cc_texture": True})


class TextureSetLoader(Module):
    """Loads one sub-folder per texture asset into the run's material library (BlenderProc's material loader
    keys); subclasses say how an asset folder reads (``read``), what marks their materials (``marker``) and
    how an asset is laid out (``layout``, for the error)."""

    role = Role.LOADER
    marker: ClassVar[str] = ""
    layout: ClassVar[str] = ""

    @staticmethod
    def params_with_folder(default: str | None) -> tuple[Param, ...]:
        """The loader keys, ``folder_path`` defaulting to ``default`` (None: required)."""
        folder = Param("folder_path", "path", doc="folder with one sub-folder per texture asset") if default is None \
            else Param("folder_path", "path", default, doc="folder with one sub-folder per texture asset")
        return (
            folder,
            Param("used_assets", "list", [], doc="only assets whose names start with one of these"),
            Param("preload", "bool", False, doc="BlenderProc's lazy loading switch; hybridgen reads images when "
                  "rendering either way"),
            Param("fill_used_empty_materials", "bool", False, doc="BlenderProc's two-phase loading switch; "
                  "hybridgen loads everything at once"),
            Param("add_custom_properties", "dict", {}, doc="extra properties of every loaded material (cp_* keys)"),
        )

    def read(self, asset: Path) -> Material | None:
        raise NotImplementedError

    def run(self, context: RunContext) -> None:
        extra = {k[3:] if k.startswith("cp_") else k: v for k, v in self.config["add_custom_properties"].items()}
        materials = asset_materials(Path(self.config["folder_path"]), [str(a) for a in self.config["used_assets"]],
                                    self.read, {self.marker: True, **extra})
        if not materials:
            raise ConfigError(f"no texture asset ({self.layout}) in '{self.config['folder_path']}'", key="folder_path")
        material_library(context).extend(materials)


@register_module("loader.CCMaterialLoader")
class CCMaterialLoader(TextureSetLoader):
    """Loads cc0textures assets as materials into the run's material library (see the module doc)."""

    marker = "is_cc_texture"
    layout = "<asset>/<asset>_2K_Color.jpg"
    params = TextureSetLoader.params_with_folder(None)

    def read(self, asset: Path) -> Material | None:
        return cc_material(asset)
