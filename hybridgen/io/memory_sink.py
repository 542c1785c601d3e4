"""A frame sink that keeps every keypoint's values in memory (for notebooks, tests, custom pipelines)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .frame_sink import PassLayout


class MemorySink:
    """Collects ``frames[i][key]`` for every keypoint i; ``records`` and ``attributes`` as given by renderers.
    ``wanted``: on-request passes to receive too (e.g. ``amodal_masks``; :mod:`hybridgen.render.passes`)."""

    values_only = True
    """``write`` keeps the values it is given and reads nothing else (so the keypoint loop may write a keypoint
    after the scene moved on to the next one: :func:`hybridgen.render.keypoint_loop.run_keypoints`)."""

    def __init__(self, wanted: Iterable[str] = ()) -> None:
        self.wanted = tuple(wanted)
        self.frames: list[dict[str, Any]] = []
        self.layouts: dict[str, PassLayout] = {}
        self.records: dict[str, np.ndarray] = {}
        self.attributes: dict[str, Any] = {}

    def wanted_passes(self) -> tuple[str, ...]:
        return self.wanted

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        while len(self.frames) < n_keypoints:
            self.frames.append({})
        self.layouts.update({layout.key: layout for layout in layouts})
        self.records.update(camera_records)
        self.attributes.update(attributes)

    def write(self, index: int, values: dict[str, Any]) -> None:
        self.frames[index].update(values)

    def end(self) -> None:
        """Nothing to flush."""

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        """Keeps ``records`` (e.g. ``object_states``) and ``attributes``; writes no file."""
        self.records.update(records or {})
        self.attributes.update(attributes or {})
        return []

    def abort(self) -> None:
        """Nothing to delete."""

    def stacked(self, key: str) -> np.ndarray:
        """All keypoints' ``key`` as one array with a leading keypoint axis."""
        return np.stack([frame[key] for frame in self.frames])
