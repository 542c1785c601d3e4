"""The view transform that turns linear RGB into 8- and 16-bit image codes: a BlenderProc 2 run's ``colors`` and
``diffuse`` images (``set_output_format(view_transform=...)``; BlenderProc 2.8's default is Filmic and Blender writes
both through it, :mod:`hybridgen.bproc.render_frames`) and ``renderer.RgbRenderer``'s ``colors`` (its
``view_transform``: Standard for hybridgen's configs, Filmic for BlenderProc 1.x ones, whose Blender 2.93 scenes
defaulted to it).

- ``Standard``: the sRGB curve (:mod:`hybridgen.render.tonemap`), exact.
- ``Filmic``: Blender's Filmic view computed from Blender's own tables (:mod:`hybridgen.render.filmic_view`), found in
  an installed ``bpy`` or Blender; equal to Blender 4.2's 8-bit codes on every value measured. Without the tables:
  Standard, with a notice saying how to get them.
- ``AgX``: Standard, with a notice (AgX's tables and its guard rails are not reproduced).

The tables are read on the encoding thread, at the first frame's encoding, not before rendering.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .filmic_view import COLORMANAGEMENT_ENV, FilmicView, find_colormanagement
from .tonemap import to_srgb16, to_srgb8


@dataclass
class LazyFilmic:
    """:class:`FilmicView` of the tables in ``folder``, read at the first encoding (thread-safe)."""

    folder: Any
    _view: FilmicView | None = None
    _lock: threading.Lock = field(default_factory=threading.Lock)

    def view(self) -> FilmicView:
        with self._lock:
            if self._view is None:
                self._view = FilmicView.from_folder(self.folder)
            return self._view

    def to_uint8(self, linear: np.ndarray) -> np.ndarray:
        return self.view().to_uint8(linear)

    def to_uint16(self, linear: np.ndarray) -> np.ndarray:
        return self.view().to_uint16(linear)


@dataclass(frozen=True)
class ColorEncoding:
    """Linear RGB (H, W, 3) to ``colors``: ``to_uint8`` and ``to_uint16``, and ``view`` (the transform they apply)."""

    view: str
    to_uint8: Callable[[np.ndarray], np.ndarray]
    to_uint16: Callable[[np.ndarray], np.ndarray]


STANDARD = ColorEncoding("Standard", to_srgb8, to_srgb16)
_FILMIC: dict[str, LazyFilmic] = {}  # per tables folder, for the process
_MATCH = ("the Standard view in both matches exactly (a script's set_output_format(view_transform='Standard'), a "
          "config renderer's view_transform: Standard)")


def color_encoding(view: str) -> ColorEncoding:
    """The encoding of BlenderProc's view transform ``view`` (``Standard``, ``Filmic``, ``AgX``); Standard with a
    notice where hybridgen cannot compute ``view``."""
    if view == "Standard":
        return STANDARD
    from ..config.notices import notice

    if view == "Filmic":
        folder = find_colormanagement()
        if folder is not None:
            lazy = _FILMIC.setdefault(str(folder), LazyFilmic(folder))
            return ColorEncoding("Filmic", lazy.to_uint8, lazy.to_uint16)
        notice("colors (and diffuse) use the Standard sRGB view: BlenderProc renders with Blender's 'Filmic' view, "
               "which hybridgen computes from Blender's own color tables, not found: run `make bpy-venv` (or install "
               f"Blender) or set {COLORMANAGEMENT_ENV} to a Blender datafiles/colormanagement folder; {_MATCH}")
        return STANDARD
    notice(f"colors (and diffuse) use the Standard sRGB view; BlenderProc renders with Blender's '{view}' view "
           f"transform, which hybridgen does not reproduce; {_MATCH}")
    return STANDARD
