"""BlenderProc renderer options about image files and texture alpha, with their meaning in hybridgen.

- ``image_type`` (``PNG`` | ``JPEG``): BlenderProc's renderer writes its color images in that format and its
  BOP and COCO writers copy those files, so ``JPEG`` gives ``rgb/*.jpg`` and ``rgb_%04d.jpg`` (BlenderProc's
  ``jpg_quality`` default 95). hybridgen's BOP and COCO writers after such a renderer write JPEG at
  quality 95 unless their own ``color_file_format`` says otherwise; HDF5 keeps the exact colors (BlenderProc
  stores the decoded JPEG there): one notice says so.
- ``use_alpha: true``: the alpha of objects' textures cuts surfaces out (Blender's alpha clip) in color and
  labels; hybridgen materials do that with ``alpha_mode: CLIP``, set here on every object's material before
  the renderer (it then holds for later renderers too: one notice says so). ``false`` (BlenderProc's default)
  is hybridgen's default ``BLEND``.
"""
from __future__ import annotations

from typing import Any

from ...errors import ConfigError
from .common import Note

JPEG_QUALITY = 95
"""BlenderProc's default ``jpg_quality`` of rendered JPEG files."""


def take_image_type(config: dict[str, Any], note: Note) -> str | None:
    """Remove ``image_type`` from a renderer's config; the format its files would have (None: not given)."""
    if "image_type" not in config:
        return None
    value = str(config.pop("image_type")).upper()
    if value not in ("PNG", "JPEG"):
        raise ConfigError(f"must be PNG or JPEG for color images, got {value!r}", key="image_type")
    if value == "JPEG":
        note(f"the BOP and COCO writers after this renderer write JPEG files (quality {JPEG_QUALITY}); HDF5 keeps "
             "the exact colors (BlenderProc stores the decoded JPEG)", "image_type")
    return value


def alpha_entries(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """``use_alpha`` removed from a renderer's config: the modules to run before the renderer."""
    if not config.pop("use_alpha", False):
        return []
    note("texture alpha cuts surfaces out (materials' alpha_mode CLIP) from here on, also for later renderers",
         "use_alpha")
    return [("manipulators.MaterialManipulator",
             {"selector": {"conditions": {}, "check_empty": False}, "material": {"alpha_mode": "CLIP"}})]


def apply_image_types(entries: list[Any], image_types: dict[int, str]) -> None:
    """BOP and COCO writers after a renderer with ``image_type`` write that format (unless they say)."""
    current = None
    for entry in entries:
        if entry.name.startswith("renderer.") and id(entry.config) in image_types:
            current = image_types[id(entry.config)]
        elif entry.name in ("writer.BopWriter", "writer.CocoAnnotationsWriter") and current is not None:
            if "color_file_format" not in entry.config:
                entry.config["color_file_format"] = current
                if current == "JPEG":
                    entry.config.setdefault("jpg_quality", JPEG_QUALITY)
