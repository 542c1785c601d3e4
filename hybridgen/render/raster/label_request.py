"""Which label passes a renderer produces: renderer options -> output keys of the pass catalogue."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Collection

import numpy as np

from ...errors import InputError
from ...io.frame_sink import PassLayout
from ...scene.scene import Scene
from .. import passes as catalogue
from ..passes import layout, pass_options, spec
from .keypoint_frame import KeypointFrame, LabelTables
from .readback import RasterOutput

MAP_BY_ALIASES = {"class": "category_id", "instance": "instance"}


@dataclass
class LabelRequest:
    """Renderer options that select label passes (docs/conventions.md sections 3 and 6).

    ``map_by`` entries: ``class`` (``category_id_segmaps``), ``instance`` (``instance_segmaps`` plus the
    per-keypoint ``instance_attribute_maps``) or the name of a numeric object attribute ``a``
    (``a_segmaps``). ``albedo``, ``flow``, ``nocs`` and ``object_records`` add those passes of
    :mod:`hybridgen.render.passes`; ``passes`` adds any other catalogue pass by key (after these). ``extra``
    names on-request passes sinks asked for; each is made when this request makes its ``with_keys``.
    """

    depth: bool = True
    distance: bool = False
    normals: bool = True
    map_by: list[str] = field(default_factory=lambda: ["class", "instance"])
    depth_background: float = float("inf")
    normals_space: str = "camera"
    albedo: bool = False
    flow: bool = False
    nocs: bool = False
    object_records: bool = False
    passes: tuple[str, ...] = ()
    extra: tuple[str, ...] = ()

    def segmap_attributes(self) -> list[str]:
        """Attributes (``category_id``, custom) that get an ``<attr>_segmaps`` pass, in order."""
        return [MAP_BY_ALIASES.get(m, m) for m in self.map_by if MAP_BY_ALIASES.get(m, m) != "instance"]

    @property
    def wants_instances(self) -> bool:
        return "instance" in self.map_by

    @property
    def wants_any(self) -> bool:
        """Whether any label pass is asked for."""
        return bool(self.keys())

    def keys(self) -> list[str]:
        """The output keys this request makes, in the order they are announced and written."""
        flags = {"depth": self.depth, "distance": self.distance, "normals": self.normals}
        keys = [key for key, wanted in flags.items() if wanted]
        keys += [f"{attribute}_segmaps" for attribute in self.segmap_attributes()]
        if self.wants_instances:
            keys += ["instance_segmaps", "instance_attribute_maps"]
        flags = {"albedo": self.albedo, "nocs": self.nocs, "object_records": self.object_records}
        keys += [key for key, wanted in flags.items() if wanted]
        if self.flow:
            keys += ["forward_flow", "forward_flow_occluded", "backward_flow", "backward_flow_occluded"]
        keys += [key for key in catalogue.PASSES if key in self.passes and key not in keys]
        return keys + [key for key in self.on_request(self.extra, keys)]

    @classmethod
    def from_options(cls, options: dict[str, Any], **settings: Any) -> "LabelRequest":
        """The request of a renderer's boolean pass options (``render_depth``, ... - every catalogue
        ``option``): options named after a field (``render_<field>``) set it, the others add their passes.
        ``settings``: the other fields (map_by, depth_background, normals_space)."""
        fields, passes = {}, []
        for option, entries in pass_options().items():
            name = option.removeprefix("render_")
            if name in cls.__dataclass_fields__:
                fields[name] = bool(options[option])
            elif options[option]:
                passes += [entry.key for entry in entries]
        return cls(**fields, **settings, passes=tuple(passes))

    @staticmethod
    def on_request(wanted: Collection[str], keys: Collection[str]) -> list[str]:
        """The on-request passes of ``wanted`` a renderer making ``keys`` makes too."""
        return [key for key in dict.fromkeys(wanted) if key in catalogue.PASSES and catalogue.PASSES[key].on_request
                and all(k in keys for k in catalogue.PASSES[key].with_keys)]

    def with_sinks(self, sinks: Collection[Any]) -> "LabelRequest":
        """This request plus the on-request passes ``sinks`` ask for (``wanted_passes()``)."""
        wanted = [key for sink in sinks for key in (getattr(sink, "wanted_passes", None) or tuple)()]
        return replace(self, extra=tuple(dict.fromkeys((*self.extra, *wanted))))

    def check_scene(self, scene: Scene, default_category_id: int | None) -> None:
        """Fail early, naming objects, if a requested segmentation attribute is missing."""
        if "category_id" in self.segmap_attributes():
            scene.require_category_ids(default_category_id)

    def layout(self, key: str, width: int, height: int) -> PassLayout:
        """Per-keypoint shape, dtype and meaning of output ``key``."""
        meaning: dict[str, Any] = {}
        if key in ("depth", "distance"):
            meaning = {"background": float(self.depth_background)}
        elif key == "normals":
            meaning = {"frame": self.normals_space}
        return layout(key, width, height, **meaning)

    def layouts(self, width: int, height: int) -> list[PassLayout]:
        """Per-keypoint shape and dtype of every output key."""
        return [self.layout(key, width, height) for key in self.keys()]

    def tables(self, view: Any) -> LabelTables:
        """Per-object lookups the keypoints share (built once per view)."""
        luts = {a: view.category_lut(a) for a in self.segmap_attributes()}
        records = {o.instance_id: {k: v for k, v in o.state().items() if k != "local2world"}
                   for o in view.scene.objects}
        return LabelTables(luts, records)

    def compute(self, frame: KeypointFrame | RasterOutput, tables: LabelTables | None = None) -> dict[str, Any]:
        """All requested values of one keypoint, each by its catalogue entry. ``frame`` may also be a bare
        readback with its ``tables`` (passes that need more than the readback then fail)."""
        if isinstance(frame, RasterOutput):
            assert tables is not None, "a bare readback needs its tables"
            frame = KeypointFrame.of_readback(frame, tables)
        values: dict[str, Any] = {}
        for key in self.keys():
            compute = spec(key).compute
            assert compute is not None, key
            values[key] = compute(frame, key)
        return values


def value_ranges(tables: LabelTables, scene: Scene) -> dict[str, np.ndarray]:
    """Id passes -> the values they can hold in ``scene`` (writers store them in the narrowest type)."""
    ranges = {f"{attribute}_segmaps": lut for attribute, lut in tables.luts.items()}
    ranges["instance_segmaps"] = np.array([0, *(o.instance_id for o in scene.objects)])
    return ranges


def parse_map_by(value: str | list[str]) -> list[str]:
    """Normalise the ``map_by`` option to a list without repeats."""
    items = [value] if isinstance(value, str) else list(value)
    if not items:
        raise InputError("map_by must name at least one of class, instance or an attribute")
    seen: list[str] = []
    for item in items:
        if item not in seen:
            seen.append(item)
    return seen
