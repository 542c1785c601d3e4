"""``loader.TextureLoader``: images loaded as textures for later use (BlenderProc's TextureLoader).

``path`` is an image file or a folder (every file directly in it, sorted by name; sub-folders are skipped);
it may be drawn (``sampler.Path``). Each image becomes an :class:`~hybridgen.scene.image_texture.ImageTexture`
of the scene named ``ct_<file name>`` (Blender's image name; a name already taken gets ``.001``), tagged with
``colorspace`` and carrying the ``add_properties`` (``cp_*``) custom properties. A file already loaded
(same resolved path) is skipped with a warning, as BlenderProc does. ``getter.Texture``
(:mod:`hybridgen.sampling.texture_getter`) selects them by name, type and custom properties; its result is
the image path, which material texture slots (``manipulators.MaterialManipulator``'s ``*_texture``) and
``displace.texture`` take. Unreadable files are one line naming the file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..input_paths import locate_input
from ..io.mesh_loader import unique_blender_name
from ..run.context import RunContext
from ..scene.image_texture import COLORSPACES, ImageTexture
from .base import Module, Role


def _properties(value: object) -> str | None:
    if not isinstance(value, dict) or any(not str(k).startswith("cp_") for k in value):
        return "loaders set only custom properties (cp_* keys), as in BlenderProc"
    return None


def read_image(path: Path) -> np.ndarray:
    """The pixels of an image file as stored (uint8, or uint16 for 16-bit files); a ConfigError naming the
    file when it is no readable image."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            image.load()
            pixels = np.asarray(image)
    except (OSError, UnidentifiedImageError, ValueError) as exc:
        raise ConfigError(f"'{path}' is not a readable image: {exc}", key="path") from None
    if pixels.dtype not in (np.uint8, np.uint16):
        pixels = pixels.astype(np.uint16 if pixels.dtype.itemsize > 1 and pixels.dtype != bool else np.uint8)
    return pixels


@register_module("loader.TextureLoader")
class TextureLoader(Module):
    """Loads an image or a folder of images as textures of the scene (see the module doc)."""

    role = Role.LOADER

    params = (
        Param("path", "str", sampleable=True, doc="an image file or a folder of images (relative to the working "
              "directory, else to the config's folder)"),
        Param("colorspace", "str", "sRGB", choices=COLORSPACES, doc="how the images' values are meant: color "
              "(sRGB) or data (Non-Color, Raw, Linear ...)"),
        Param("add_properties", "dict", {}, check=_properties, doc="cp_* custom properties of every texture"),
    )

    def run(self, context: RunContext) -> None:
        given = str(self.value(context, "path"))
        path = Path(locate_input(given))
        if path.is_dir():
            files = sorted(p for p in path.iterdir() if p.is_file())
            skipped = sorted(p.name for p in path.iterdir() if p.is_dir())
            if skipped:
                context.log(f"{self.module_name}: sub-folders are not read: {', '.join(skipped)}")
        elif path.is_file():
            files = [path]
        else:
            raise ConfigError(f"no image file or folder at '{given}'", key="path")
        textures = context.scene.textures
        loaded = {str(Path(t.path).resolve()) for t in textures}
        taken = {t.name for t in textures}
        properties = {k[3:]: v for k, v in self.config["add_properties"].items()}
        for file in files:
            resolved = str(file.resolve())
            if resolved in loaded:
                context.log(f"{self.module_name}: '{file}' is loaded already; skipped (load a copy of "
                            "the file for another colorspace)", "warning")
                continue
            name = unique_blender_name(f"ct_{file.name}", taken)
            textures.append(ImageTexture(name, str(file), self.config["colorspace"], read_image(file),
                                         dict(properties)))
            loaded.add(resolved)
            taken.add(name)
