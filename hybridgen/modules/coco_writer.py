"""``writer.CocoAnnotationsWriter``: COCO instance annotations (``images/`` + ``coco_annotations.json``)."""
from __future__ import annotations

from ..config.options import from_config, option_params
from ..config.registry import register_module
from ..config.schema import Param
from ..io.coco_writer import NEEDED_KEYS, CocoOptions, CocoWriter, image_key_hint
from ..io.renamed_sink import renamed_sinks
from ..run.context import RunContext
from .base import Module, Role


@register_module("writer.CocoAnnotationsWriter")
class CocoAnnotationsWriter(Module):
    """Writes images/ and coco_annotations.json (RLE or polygon masks from the exact instance map)."""

    role = Role.WRITER
    shares_files_across_units = True

    params = (
        Param("output_dir", "path", doc="dataset folder (usually from global.all)"),
        *option_params(CocoOptions),
        Param("segcolormap_output_key", "str", "instance_attribute_maps", doc="the key the renderer stores "
              "instance_attribute_maps under (its output_keys; BlenderProc's segcolormap_output_key)"),
        Param("segmap_output_key", "str", "instance_segmaps", doc="the key the renderer stores instance_segmaps "
              "under (its output_keys)"),
    )

    def _stored(self) -> dict[str, str]:
        """The instance passes by the names the renderers store them under -> their own names."""
        return {self.config["segcolormap_output_key"]: "instance_attribute_maps",
                self.config["segmap_output_key"]: "instance_segmaps"}

    def consumes(self) -> dict[str, str]:
        image_key = self.config["rgb_output_key"]
        return {image_key: image_key_hint(image_key), **{key: NEEDED_KEYS[own] for key, own in self._stored().items()}}

    def prepare(self, context: RunContext) -> None:
        cfg = self.config
        renamed = {key: own for key, own in self._stored().items() if key != own}
        self.writer = CocoWriter(cfg["output_dir"], from_config(CocoOptions, cfg))
        context.sinks += renamed_sinks([self.writer], renamed)  # reads the renamed passes by their roles
        context.cleanups.append(self.writer.abort)

    def run(self, context: RunContext) -> None:
        context.outputs += self.writer.finalize()
