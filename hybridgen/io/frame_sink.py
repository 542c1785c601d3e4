"""The interface between renderers and writers: per-keypoint records streamed as they are rendered."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np


@dataclass(frozen=True)
class PassLayout:
    """Shape and dtype of one output key per keypoint; ``dtype`` 'json' marks a JSON text value."""

    key: str
    dtype: str
    shape: tuple[int, ...]
    value_range: tuple[int, int] | None = None  # integer passes: the lowest and highest value they can hold


class FrameSink(Protocol):
    """Receives a renderer's keypoints. ``begin`` once per renderer, then ``write`` per keypoint, then ``end``."""

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None: ...

    def write(self, index: int, values: dict[str, Any]) -> None: ...

    def end(self) -> None: ...
