"""Poly Haven assets: ``loader.HavenEnvironmentLoader`` (an HDRI as the world) and ``loader.HavenMaterialLoader``
(PBR texture sets into the material library).

HDRIs are read from BlenderProc's download layout, ``<data_path>/hdris/<name>/<name>_<res>.hdr``: every
``.hdr`` (and ``.exr``) one folder below ``hdris``, sorted by path, one drawn with the run's random generator
(BlenderProc draws with Python's ``random`` from the same sorted list). The world then emits the HDRI
times ``strength``, turned by ``rotation`` radians about world +Z (hybridgen keys; BlenderProc's loader
has neither, its world strength is 1 and the map unturned).
"""
from __future__ import annotations

from pathlib import Path

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.texture_sets import haven_material
from ..run.context import RunContext
from ..scene.material import Material
from .base import Module, Role
from .material_library import TextureSetLoader

HDRI_SUFFIXES = (".hdr", ".exr")


def haven_hdris(data_path: Path) -> list[Path]:
    """The HDRI files of a Poly Haven download folder, sorted; a one-line error for a wrong folder."""
    if not data_path.is_dir():
        raise ConfigError(f"Haven data folder not found: '{data_path}'", key="data_path")
    hdris = data_path / "hdris"
    if not hdris.is_dir():
        raise ConfigError(f"'{data_path}' has no 'hdris' folder (expected <data_path>/hdris/<name>/<name>.hdr, "
                          "BlenderProc's download layout)", key="data_path")
    files = sorted(p for p in hdris.glob("*/*") if p.is_file() and p.suffix.lower() in HDRI_SUFFIXES)
    if not files:
        raise ConfigError(f"no .hdr/.exr file in the sub-folders of '{hdris}'", key="data_path")
    return files


@register_module("loader.HavenEnvironmentLoader")
class HavenEnvironmentLoader(Module):
    """Sets the world to a randomly drawn HDRI of a Poly Haven folder (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("data_path", "path", "resources/haven", doc="Poly Haven download folder holding 'hdris/'"),
        Param("strength", "float", 1.0, doc="multiplies the HDRI's radiance", sampleable=True),
        Param("rotation", "float", 0.0, "rad", "turn of the map about world +Z", sampleable=True),
    )

    def run(self, context: RunContext) -> None:
        files = haven_hdris(Path(self.config["data_path"]))
        strength = float(self.value(context, "strength"))
        if strength < 0:
            raise ConfigError(f"must be >= 0, got {strength}", key="strength")
        world = context.scene.world
        world.hdri_path = str(files[int(context.rng.integers(len(files)))])
        world.strength = strength
        world.hdri_rotation = float(self.value(context, "rotation"))


@register_module("loader.HavenMaterialLoader")
class HavenMaterialLoader(TextureSetLoader):
    """Loads Poly Haven texture sets (``<asset>/<asset>_diff_2k.jpg`` + maps, see
    :mod:`hybridgen.io.texture_sets`) into the run's material library, with ``is_haven_texture: true``."""

    marker = "is_haven_texture"
    layout = "<asset>/<asset>_diff_2k.jpg"
    params = TextureSetLoader.params_with_folder("resources/haven/textures")

    def read(self, asset: Path) -> Material | None:
        return haven_material(asset)
