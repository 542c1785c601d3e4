"""Renderer outputs stored under other names: BlenderProc's ``output_key`` / ``*_output_key`` (a renderer
names the dataset a pass is stored under). The renaming happens between a renderer and its sinks, so every
writer of the run sees the pass under the new name, as BlenderProc's writers do."""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Mapping

import numpy as np

from ..errors import ConfigError
from .frame_sink import FrameSink, PassLayout, SinkFilter


def check_output_keys(value: Any) -> str | None:
    """Param check: ``{pass name: stored name}`` with distinct, non-empty plain names."""
    if value is None:
        return None
    if not isinstance(value, dict) or not all(isinstance(k, str) and isinstance(v, str) and v and "/" not in v
                                              for k, v in value.items()):
        return f"must map pass names to dataset names (text without '/'), got {value!r}"
    if len(set(value.values())) != len(value):
        return f"two passes would be stored under one name: {value!r}"
    return None


def renamed_layouts(layouts: list[PassLayout], names: Mapping[str, str]) -> list[PassLayout]:
    """``layouts`` with their keys renamed. A name for a pass the renderer does not write this time is no
    error (BlenderProc's renderers take ``depth_output_key`` whether or not they render depth); two passes
    stored under one name are."""
    out = [replace(layout, key=names.get(layout.key, layout.key)) for layout in layouts]
    stored = [layout.key for layout in out]
    clash = sorted({k for k in stored if stored.count(k) > 1})
    if clash:
        raise ConfigError(f"output_keys stores two passes as {clash}", key="output_keys")
    return out


class RenamedSink(SinkFilter):
    """A :class:`~hybridgen.io.frame_sink.FrameSink` that hands ``sink`` every pass under ``names[pass]``
    (passes not named keep their name); anything else is the wrapped sink's."""

    def __init__(self, sink: FrameSink, names: Mapping[str, str]) -> None:
        super().__init__(sink)
        self.names = dict(names)

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        self.sink.begin(n_keypoints, renamed_layouts(layouts, self.names), camera_records, attributes)

    def write(self, index: int, values: dict[str, Any]) -> None:
        self.sink.write(index, {self.names.get(k, k): v for k, v in values.items()})


def renamed_sinks(sinks: list[FrameSink], names: Mapping[str, str] | None) -> list[FrameSink]:
    """``sinks`` as they should receive a renderer's passes (unchanged without renames)."""
    if not names:
        return sinks
    return [RenamedSink(sink, names) for sink in sinks]
