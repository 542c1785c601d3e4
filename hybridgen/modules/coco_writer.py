"""``writer.CocoAnnotationsWriter``: COCO instance annotations (``images/`` + ``coco_annotations.json``)."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..io.coco_writer import (COLOR_FORMATS, DEFAULT_SUPERCATEGORY, IMAGE_NAMES, MASK_ENCODINGS, NEEDED_KEYS,
                              CocoWriter, image_key_hint, load_label_mapping)
from ..io.renamed_sink import renamed_sinks
from ..run.context import RunContext
from .base import Module, Role
from .writer_support import refuse_work_units


def _prefix_check(value: str) -> str | None:
    return f"must be a plain file name prefix (no '/'), got {value!r}" if "/" in value or "\\" in value else None


@register_module("writer.CocoAnnotationsWriter")
class CocoAnnotationsWriter(Module):
    """Writes images/ and coco_annotations.json (RLE or polygon masks from the exact instance map)."""

    role = Role.WRITER

    params = (
        Param("output_dir", "path", doc="dataset folder (usually from global.all)"),
        Param("rgb_output_key", "str", "colors", doc="uint8 image key written to images/"),
        Param("mask_encoding_format", "str", "rle", choices=MASK_ENCODINGS,
              doc="rle: compressed RLE (pycocotools, exact); polygon: exact pixel outlines (holes filled)"),
        Param("color_file_format", "str", "PNG", choices=COLOR_FORMATS, doc="image file format"),
        Param("jpg_quality", "int", 95, doc="JPEG quality 1..100",
              check=lambda v: None if 1 <= v <= 100 else f"must be in 1..100, got {v}"),
        Param("supercategory", "str", DEFAULT_SUPERCATEGORY, doc="only objects whose 'supercategory' (or "
              "'bop_dataset_name') attribute is this; the default takes every object"),
        Param("label_mapping", "dict|path|null", None, doc="category names: {category_id: name} or a CSV file with "
              "id,name columns; default: the name of the first object of the category"),
        Param("append_to_existing_output", "bool", False, doc="extend an existing coco_annotations.json: image and "
              "annotation ids continue after its highest ones"),
        Param("file_prefix", "str", "", doc="prefix of the image file names", check=_prefix_check),
        Param("image_names", "str", "hybridgen", choices=IMAGE_NAMES, doc="hybridgen: images/<prefix><id:06d>.png; "
              "blenderproc: BlenderProc's <prefix>rgb_<id:04d>.png next to coco_annotations.json, file_name "
              "'<folder>/rgb_0000.png' (the default for configs in BlenderProc's form)"),
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
        refuse_work_units(context, self.module_name)
        renamed = {key: own for key, own in self._stored().items() if key != own}
        self.writer = CocoWriter(cfg["output_dir"], image_key=cfg["rgb_output_key"],
                                 mask_encoding=cfg["mask_encoding_format"], color_file_format=cfg["color_file_format"],
                                 jpg_quality=cfg["jpg_quality"], supercategory=cfg["supercategory"],
                                 label_mapping=load_label_mapping(cfg["label_mapping"]),
                                 append=cfg["append_to_existing_output"], file_prefix=cfg["file_prefix"],
                                 image_names=cfg["image_names"])
        context.sinks += renamed_sinks([self.writer], renamed)  # reads the renamed passes by their roles
        context.cleanups.append(self.writer.abort)

    def run(self, context: RunContext) -> None:
        context.outputs += self.writer.finalize()
