"""BlenderProc's one ``segmap`` dataset: a channel per numeric ``map_by`` attribute, for configs in BlenderProc's
form.

BlenderProc's SegMapRenderer stores one image per keypoint (``output_key``, default ``segmap``) whose channels
are its ``map_by`` entries in order - ``instance`` (the object's id), ``class`` (``category_id``) and every
attribute whose values are numbers - squeezed to H x W when there is one channel. Attributes that are not
numbers (``name``, text custom properties) get no channel: they are in the per-keypoint attribute map (here
``instance_attribute_maps``). ``default_values`` give objects that lack an attribute that value (``class`` is
``category_id``); without one, a missing attribute is an error, as in BlenderProc. An attribute that only
default values fill - no object holds a value of its own - gets no channel either (BlenderProc keeps a channel
only when a value not taken from ``default_values`` was used; it decides per frame among the visible objects,
hybridgen once per scene among all objects, because the segmap dataset has one layout for every keypoint);
when that leaves no channel at all, the run stops with one line, as BlenderProc's stacking of no channel does.

hybridgen renders each attribute as its own ``<attr>_segmaps`` pass; :class:`SegmapSink` stacks them into the
``segmap`` dataset in front of the writers, which still get the per-attribute passes too.
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass, replace
from typing import Any, Mapping

import numpy as np

from ..errors import InputError
from ..scene.scene import Scene
from .frame_sink import FrameSink, PassLayout, SinkFilter

_ATTRIBUTE = {"class": "category_id", "category_id": "category_id"}


@dataclass(frozen=True)
class SegmapPlan:
    """What to render for a BlenderProc ``map_by`` on one scene: hybridgen's ``map_by`` and the passes that
    become the ``segmap`` channels, in order."""

    map_by: list[str]
    channels: list[str]


def _value(obj: Any, attribute: str) -> Any:
    return obj.category_id if attribute == "category_id" else obj.attributes.get(attribute)


def _numeric(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


_DEFAULTED: "weakref.WeakKeyDictionary[Any, set[str]]" = weakref.WeakKeyDictionary()
"""Per object, the attributes it holds because ``default_values`` gave them (not its own values)."""


def apply_default_values(scene: Scene, defaults: Mapping[str, Any]) -> None:
    """Objects lacking an attribute of ``defaults`` (``class`` / ``cp_<name>`` / ``<name>``) get its value
    (remembered as a default value, see :func:`segmap_plan`)."""
    for key, value in defaults.items():
        attribute = key[3:] if key.startswith("cp_") else _ATTRIBUTE.get(key, key)
        for obj in scene.objects:
            if _value(obj, attribute) is not None:
                continue
            if attribute == "category_id":
                obj.category_id = int(value) if _numeric(value) else value
            else:
                obj.attributes[attribute] = value
            _DEFAULTED.setdefault(obj, set()).add(attribute)


def only_defaults(scene: Scene, attribute: str) -> bool:
    """Whether every object holds ``attribute`` only because ``default_values`` gave it."""
    return all(attribute in _DEFAULTED.get(obj, ()) for obj in scene.objects)


def segmap_plan(scene: Scene, map_by: list[str]) -> SegmapPlan:
    """Channels of BlenderProc's segmap for ``map_by`` (hybridgen names: ``instance``, ``class``, attributes).
    An attribute every object holds as a number is a channel; one no object holds as a number is left to the
    attribute map; a mix, or one some object lacks, is an error naming the object."""
    rendered, channels, dropped = [], [], []
    for entry in map_by:
        if entry == "instance":
            rendered.append(entry)
            channels.append("instance_segmaps")
            continue
        attribute = _ATTRIBUTE.get(entry, entry)
        values = {obj.name: _value(obj, attribute) for obj in scene.objects}
        missing = [name for name, value in values.items() if value is None]
        if missing:
            raise InputError(f"object '{missing[0]}' has no '{entry}' to map segmentation by; give it one or set "
                             f"SegMapRenderer's default_values")
        numeric = [_numeric(value) for value in values.values()]
        if all(numeric) and only_defaults(scene, attribute):
            rendered.append(entry)  # hybridgen's own <attr>_segmaps pass stays (writers may read it) ...
            dropped.append(entry)  # ... but BlenderProc drops a channel no value of an object's own went into
            continue
        if all(numeric):
            rendered.append(entry)
            channels.append(f"{attribute}_segmaps")
        elif any(numeric):
            raise InputError(f"'{entry}' holds numbers on some objects and text on others: BlenderProc's "
                             "segmap needs one kind per attribute (check default_values' type)")
    if dropped and not channels:
        raise InputError(f"every object takes {', '.join(dropped)} from default_values: BlenderProc's segmap would "
                         "have no channel (BlenderProc stops here too); give the objects their own values or map "
                         "by instance as well")
    return SegmapPlan(rendered, channels)


class SegmapSink(SinkFilter):
    """Hands ``sink`` the renderer's passes plus ``key``: the ``channels`` passes stacked on a last axis
    (H x W with one channel), stored in the smallest integer range that holds them all."""

    def __init__(self, sink: FrameSink, channels: list[str], key: str) -> None:
        super().__init__(sink)
        self.channels, self.key = list(channels), key

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        by_key = {layout.key: layout for layout in layouts}
        parts = [by_key[c] for c in self.channels if c in by_key]
        if parts and len(parts) == len(self.channels):
            ranges = [p.value_range for p in parts if p.value_range is not None]
            shape = parts[0].shape if len(parts) == 1 else (*parts[0].shape, len(parts))
            value_range = (min(r[0] for r in ranges), max(r[1] for r in ranges)) if ranges else None
            layouts = [*layouts, replace(parts[0], key=self.key, shape=shape, value_range=value_range, units="")]
        self.sink.begin(n_keypoints, layouts, camera_records, attributes)

    def write(self, index: int, values: dict[str, Any]) -> None:
        if self.channels and all(c in values for c in self.channels):
            stacked = np.stack([np.asarray(values[c]) for c in self.channels], axis=-1)
            values = {**values, self.key: stacked[..., 0] if len(self.channels) == 1 else stacked}
        self.sink.write(index, values)
