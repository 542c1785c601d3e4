"""``renderer.SegMapRenderer``: the labels-only renderer (depth, distance, normals, segmentation)."""
from __future__ import annotations

from typing import Any

from ..config.registry import register_module
from ..config.schema import Param
from ..io.blenderproc_segmap import SegmapSink, apply_default_values, segmap_plan
from ..io.renamed_sink import renamed_sinks
from ..render.raster.label_request import parse_map_by
from ..render.raster.render_labels import render_labels
from ..render.raster.threaded_labels import auto_render_threads
from ..run.context import RunContext
from .base import Module, Role
from .label_params import label_params, label_request, stored_keys


def _threads_check(value: Any) -> str | None:
    if value == "auto" or (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
        return None
    return f"must be 'auto' or an integer >= 1, got {value!r}"


def _segmap_check(value: Any) -> str | None:
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) - {"key", "default_values"} or \
            not isinstance(value.get("key", "segmap"), str) or not isinstance(value.get("default_values", {}), dict):
        return f"must be {{key: name, default_values: {{attribute: value}}}}, got {value!r}"
    return None


@register_module("renderer.SegMapRenderer")
class SegMapRenderer(Module):
    """Rasterizes the selected label passes of every keypoint and streams them to the writers."""

    role = Role.RENDERER

    params = (*label_params(depth=True, normals=True, map_by=["class", "instance"]),
              Param("blenderproc_segmap", "dict|null", None, check=_segmap_check,
                    doc="also store BlenderProc's one segmap, {key, default_values}: a channel per numeric map_by "
                    "attribute in order (text attributes only in instance_attribute_maps); objects lacking an "
                    "attribute get its default value (set by BlenderProc configs)"),
              Param("render_threads", "int|str", "auto", check=_threads_check,
                    doc="raster threads, each with its own GL context and copy of the geometry; auto: 2 for "
                    "32+ keypoints of a scene of 1M+ triangles on 2+ cores, else 1 (docs/label_pipeline.md); "
                    "same bytes whatever the count"))

    def produces(self) -> frozenset[str] | None:
        segmap = self.config["blenderproc_segmap"]
        return stored_keys(self.config, [segmap.get("key", "segmap")] if segmap is not None else [])

    def run(self, context: RunContext) -> None:
        config, segmap = self.config, self.config["blenderproc_segmap"]
        sinks = renamed_sinks(context.sinks, config["output_keys"])
        if segmap is not None and config["map_by"] is not None:
            apply_default_values(context.scene, segmap.get("default_values", {}))
            plan = segmap_plan(context.scene, parse_map_by(config["map_by"]))
            config = {**config, "map_by": plan.map_by or None}
            sinks = [SegmapSink(sink, plan.channels, segmap.get("key", "segmap")) for sink in sinks]
        threads = config["render_threads"]
        if threads == "auto":
            threads = auto_render_threads(context.scene.triangle_count, len(context.keypoint_indices()))
        request = label_request(config)
        context.frames_rendered += render_labels(context.scene, sinks, request,
                                                 default_category_id=context.default_category_id,
                                                 progress=context.progress,
                                                 indices=context.keypoint_indices(),
                                                 render_threads=threads)
