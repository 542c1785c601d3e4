"""Which label passes a renderer produces, and how each keypoint's values are made from one raster draw."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..io.frame_sink import PassLayout
from ..scene.scene import Scene
from .passes import PASSES, RasterOutput

MAP_BY_ALIASES = {"class": "category_id", "instance": "instance"}


@dataclass
class LabelRequest:
    """Renderer options that select label passes (docs/conventions.md sections 3 and 6).

    ``map_by`` entries: ``class`` (``category_id_segmaps``), ``instance`` (``instance_segmaps`` plus the
    per-keypoint ``instance_attribute_maps``) or the name of a numeric object attribute ``a``
    (``a_segmaps``). ``albedo``, ``flow``, ``nocs`` and ``object_records`` add the passes of
    :mod:`hybridgen.render.albedo_pass`, :mod:`hybridgen.render.geometry_passes` and
    :mod:`hybridgen.render.object_records`.
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

    def segmap_attributes(self) -> list[str]:
        """Attributes (``category_id``, custom) that get an ``<attr>_segmaps`` pass, in order."""
        return [MAP_BY_ALIASES.get(m, m) for m in self.map_by if MAP_BY_ALIASES.get(m, m) != "instance"]

    @property
    def wants_instances(self) -> bool:
        return "instance" in self.map_by

    def check_scene(self, scene: Scene, default_category_id: int | None) -> None:
        """Fail early, naming objects, if a requested segmentation attribute is missing."""
        if "category_id" in self.segmap_attributes():
            scene.require_category_ids(default_category_id)

    def layouts(self, width: int, height: int) -> list[PassLayout]:
        """Per-keypoint shape and dtype of every output key."""
        out: list[PassLayout] = []
        for flag, key in ((self.depth, "depth"), (self.distance, "distance"), (self.normals, "normals")):
            if flag:
                spec = PASSES[key]
                meaning = ({"frame": self.normals_space} if key == "normals"
                           else {"units": "m", "background": float(self.depth_background)})
                out.append(PassLayout(key, spec.dtype, (height, width, spec.channels) if spec.channels
                                      else (height, width), **meaning))
        for attribute in self.segmap_attributes():
            out.append(PassLayout(f"{attribute}_segmaps", "int32", (height, width)))
        if self.wants_instances:
            out.append(PassLayout("instance_segmaps", "int32", (height, width)))
            out.append(PassLayout("instance_attribute_maps", "json", ()))
        if self.albedo:
            out.append(PassLayout("albedo", "float32", (height, width, 3)))
        if self.nocs:
            out.append(PassLayout("nocs", "float32", (height, width, 3)))
        if self.object_records:
            out.append(PassLayout("object_records", "json", ()))
        if self.flow:
            for direction in ("forward", "backward"):
                out.append(PassLayout(f"{direction}_flow", "float32", (height, width, 2)))
                out.append(PassLayout(f"{direction}_flow_occluded", "uint8", (height, width)))
        return out

    def tables(self, view: Any) -> "LabelTables":
        """Per-object lookups the keypoints share (built once per view)."""
        luts = {a: view.category_lut(a) for a in self.segmap_attributes()}
        records = {o.instance_id: {k: v for k, v in o.state().items() if k != "local2world"}
                   for o in view.scene.objects}
        return LabelTables(luts, records)

    def compute(self, raw: RasterOutput, tables: "LabelTables") -> dict[str, Any]:
        """All requested values of one keypoint from its raster readback."""
        values: dict[str, Any] = {}
        for flag, key in ((self.depth, "depth"), (self.distance, "distance"), (self.normals, "normals")):
            if flag:
                values[key] = PASSES[key].compute(raw)
        for attribute, lut in tables.luts.items():
            values[f"{attribute}_segmaps"] = lut[raw.instance]
        if self.wants_instances:
            values["instance_segmaps"] = raw.instance.astype(np.int32)
            values["instance_attribute_maps"] = tables.visible(raw.instance)
        return values


@dataclass
class LabelTables:
    """``luts``: instance id -> segmap value per attribute; ``records``: instance id -> JSON record."""

    luts: dict[str, np.ndarray]
    records: dict[int, dict[str, Any]]

    def visible(self, instance: np.ndarray) -> list[dict[str, Any]]:
        """``[{"idx", "category_id", "name", custom attributes...}]`` of each instance in the map, by id."""
        present = np.flatnonzero(np.bincount(instance.ravel()))
        return [self.records[int(i)] for i in present if i != 0]


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
