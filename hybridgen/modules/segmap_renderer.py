"""``renderer.SegMapRenderer``: the labels-only renderer (depth, distance, normals, segmentation)."""
from __future__ import annotations

from ..config.registry import register_module
from ..io.renamed_sink import renamed_sinks
from ..render.render_labels import render_labels
from ..run.context import RunContext
from .base import Module, Role
from .label_params import label_params, label_request, stored_keys


@register_module("renderer.SegMapRenderer")
class SegMapRenderer(Module):
    """Rasterizes the selected label passes of every keypoint and streams them to the writers."""

    role = Role.RENDERER

    params = label_params(depth=True, normals=True, map_by=["class", "instance"])

    def produces(self) -> frozenset[str] | None:
        return stored_keys(self.config)

    def run(self, context: RunContext) -> None:
        sinks = renamed_sinks(context.sinks, self.config["output_keys"])
        context.frames_rendered += render_labels(context.scene, sinks, label_request(self.config),
                                                 default_category_id=context.default_category_id,
                                                 progress=context.progress,
                                                 indices=context.keypoint_indices())
