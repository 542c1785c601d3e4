"""The interface between renderers and writers: per-keypoint records streamed as they are rendered.

A renderer describes each output key once, per run, with a typed :class:`PassLayout` (shape, dtype, units,
axes, background, stereo); writers take every meaning they need from it - never from the run's
``attributes``, which are opaque values a writer may record (seed, renderer settings, ...) - and never
guess from key names. The pass catalogue (:mod:`hybridgen.render.passes`) fills these fields.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Collection, Protocol

import numpy as np


@dataclass(frozen=True)
class PassLayout:
    """One output key per keypoint: ``shape`` and ``dtype`` of its value (``dtype`` 'json': a JSON-ready
    value, shape ``()``), and what the numbers mean.

    ``value_range``: integer passes, the lowest and highest value they can hold (writers pick storage from
    it). ``units``: of the values ('m', 'px', 'sRGB', ...; empty when unitless). ``frame``: axes of vector
    values ('camera' = OpenCV camera axes, 'world'; empty when not a vector). ``background``: the value of
    pixels where no surface was hit (None when the pass has none or it is 0). ``stereo``: the shape starts
    with an axis of 2 (left, right eye).
    """

    key: str
    dtype: str
    shape: tuple[int, ...]
    value_range: tuple[int, int] | None = None
    units: str = ""
    frame: str = ""
    background: float | None = None
    stereo: bool = False

    @property
    def image_size(self) -> tuple[int, int] | None:
        """``(height, width)`` in pixels of an image-like pass, None for JSON values and Python objects
        (on-request passes, :mod:`hybridgen.render.passes`)."""
        if self.dtype in ("json", "object"):
            return None
        first = 1 if self.stereo else 0
        height, width = self.shape[first:first + 2]
        return int(height), int(width)


class FrameSink(Protocol):
    """Receives renderers' keypoints and turns them into files.

    Per renderer: ``begin`` once, ``write`` per keypoint (0..n-1), ``end``. After every renderer either
    ``finalize`` - commit, returning the files (or folders) written, in a stable order - or ``abort`` -
    leave nothing under a final name. ``records`` and ``attributes`` of ``finalize`` are scene-level JSON
    records (``object_states``, ...) and run attributes (seed, resolved config, ...) for writers that store
    them; others ignore them.

    A sink may also have ``wanted_passes() -> tuple[str, ...]``: the on-request passes (``amodal_masks``,
    ``visible_fractions``, ``object_boxes``; :mod:`hybridgen.render.passes`) renderers then hand to it, and
    only to it, with ``instance_segmaps``.
    """

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None: ...

    def write(self, index: int, values: dict[str, Any]) -> None: ...

    def end(self) -> None: ...

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]: ...

    def abort(self) -> None: ...



class SinkFilter:
    """A sink in front of another (``sink``): every call goes on to it unchanged; subclasses change what
    ``begin`` and ``write`` hand on (renamed keys, derived passes, ...)."""

    def __init__(self, sink: FrameSink) -> None:
        self.sink = sink

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        self.sink.begin(n_keypoints, layouts, camera_records, attributes)

    def write(self, index: int, values: dict[str, Any]) -> None:
        self.sink.write(index, values)

    def end(self) -> None:
        self.sink.end()

    def wanted_passes(self) -> tuple[str, ...]:
        """The on-request passes the sink behind asks for."""
        wanted = getattr(self.sink, "wanted_passes", None)
        return tuple(wanted()) if wanted is not None else ()

    def wanted_objects(self) -> Collection[int] | None:
        """The objects (instance ids) whose per-object passes the sink behind reads; None: all."""
        wanted = getattr(self.sink, "wanted_objects", None)
        return wanted() if wanted is not None else None

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        return self.sink.finalize(records, attributes)

    def abort(self) -> None:
        self.sink.abort()
