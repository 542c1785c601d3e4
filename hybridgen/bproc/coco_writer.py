"""``bproc.writer.write_coco_annotations``: BlenderProc 2.8's COCO instance annotations
(https://cocodataset.org/#format-data) of the session's frames, from render()'s segmentation and colors.

What and where, as BlenderProc writes it (the files are written by hybridgen's COCO writer,
:class:`hybridgen.io.coco_writer.CocoWriter`, in BlenderProc's form by :class:`BlenderProcCocoSink`)::

    <output_dir>/images/<file_prefix><image id:06d>.png|.jpg     the colors of each frame
    <output_dir>/coco_annotations.json

- One annotation per instance visible in a frame's ``instance_segmaps`` whose ``instance_attribute_maps`` entry has
  a non-zero ``category_id`` and whose ``bop_dataset_name`` (else ``supercategory``, else ``coco_annotations``) is
  ``supercategory`` - or every object with the default ``coco_annotations``. ``segmentation``: BlenderProc's
  uncompressed RLE (``{"counts": [runs, column-major, from a background run], "size": [h, w]}``) or, with
  ``mask_encoding_format="polygon"``, polygons; ``bbox`` ``[x, y, w, h]`` and ``area`` in pixels; ``iscrowd`` 0.
- Categories: ``id`` = ``category_id``, ``name`` from ``label_mapping`` (BlenderProc's ``LabelIdMapping``, anything
  with ``label_from_id``, or a ``{id: name}`` dict / CSV path), else the object's ``name`` attribute, else the id.
- ``info``, ``licenses`` and the image entries' ``date_captured``/``license``/``coco_url``/``flickr_url`` as
  BlenderProc writes them (timestamps in UTC); ``indent`` as ``json.dump``'s.
- ``append_to_existing_output`` (default True): image ids and file numbers continue after the highest image id
  of an existing ``coco_annotations.json``, annotation ids after its highest annotation id.

Differences: polygons trace each mask's pixel outlines exactly (pycocotools decodes them to the mask; BlenderProc's
skimage contours through pixel centres, simplified with tolerance 2, do not); categories are listed by id and
merged by id when appending (BlenderProc: first-seen order, merged by equal entries); an instance missing from
``instance_attribute_maps`` is an error (BlenderProc skips it). Files are staged and renamed when complete.
"""
from __future__ import annotations

import datetime
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..errors import InputError
from ..io.coco_writer import CocoWriter
from .session import SESSION

COCO_LICENSES = [{"id": 1, "name": "Attribution-NonCommercial-ShareAlike License",
                  "url": "http://creativecommons.org/licenses/by-nc-sa/2.0/"}]
"""The ``licenses`` section BlenderProc writes (pycococreator's)."""


def utc_now() -> str:
    """The current UTC time as BlenderProc stamps its COCO files (``YYYY-MM-DD HH:MM:SS.ffffff``)."""
    return datetime.datetime.now(datetime.timezone.utc).replace(tzinfo=None).isoformat(" ")


class BlenderProcCocoSink(CocoWriter):
    """hybridgen's COCO writer writing BlenderProc 2's form: uncompressed RLE, its ``info``/``licenses`` and image
    keys, category names from a ``LabelIdMapping``, ``indent``."""

    compressed_rle = False

    def __init__(self, output_dir: str | Path, options: Any, indent: int | str | None, id_labels: Any) -> None:
        super().__init__(output_dir, options)
        self.indent, self.id_labels = indent, id_labels

    def _category_name(self, record: dict[str, Any], category: int) -> Any:
        if self.id_labels is not None:
            return self.id_labels.label_from_id(category)
        return record["name"] if "name" in record else category

    def _content(self) -> dict[str, Any]:
        stamp = utc_now()
        for image in self.images.values():
            image.update({"date_captured": stamp, "license": 1, "coco_url": "", "flickr_url": ""})
        content = super()._content()
        if self.existing is None:
            content["info"] = {"description": self.supercategory, "url": "https://github.com/waspinator/pycococreator",
                               "version": "0.1.0", "year": 2020, "contributor": "Unknown", "date_created": stamp}
            content["licenses"] = COCO_LICENSES
        return content


def write_coco_annotations(output_dir: str, instance_segmaps: Sequence[np.ndarray],
                           instance_attribute_maps: Sequence[list[dict[str, Any]]], colors: Sequence[np.ndarray],
                           color_file_format: str = "PNG", mask_encoding_format: str = "rle",
                           supercategory: str = "coco_annotations", append_to_existing_output: bool = True,
                           jpg_quality: int = 95, label_mapping: Any = None, file_prefix: str = "",
                           indent: int | str | None = None) -> None:
    """Write ``<output_dir>/coco_annotations.json`` and ``images/`` of the session's frames (see the module
    documentation): one instance map (int, 0 = background), attribute map list and uint8 color image per frame."""
    from ..config.options import checked_options
    from ..io.coco_writer import CocoOptions
    from ..io.frame_sink import PassLayout

    count = SESSION.frame_end - SESSION.frame_start
    if len(colors) > 0 and np.asarray(colors[0]).ndim == 4:
        raise InputError("BlenderProc currently does not support writing coco annotations for stereo images; "
                         "enter left and right images / segmaps separately")
    for name, values in (("colors", colors), ("instance_segmaps", instance_segmaps),
                         ("instance_attribute_maps", instance_attribute_maps)):
        if len(values) != count:
            raise InputError(f"bproc.writer.write_coco_annotations: {len(values)} {name} for {count} frames "
                             "(frame_start to frame_end)")
    if any("category_id" not in record for records in instance_attribute_maps for record in records):
        raise InputError("bproc.writer.write_coco_annotations: instance_attribute_maps have no category_id; render "
                         "with bproc.renderer.enable_segmentation_output(map_by=['category_id', 'instance', ...])")
    mapping = None if label_mapping is None or hasattr(label_mapping, "label_from_id") else label_mapping
    if mapping is not None and not isinstance(mapping, (Mapping, str, Path)):
        raise InputError(f"label_mapping must be a LabelIdMapping (label_from_id), a dict or a CSV path, "
                         f"got {type(label_mapping).__name__}")
    options = checked_options(CocoOptions, mask_encoding=mask_encoding_format, color_file_format=color_file_format,
                              jpg_quality=int(jpg_quality), supercategory=supercategory,
                              append=bool(append_to_existing_output), file_prefix=file_prefix, label_mapping=mapping)
    sink = BlenderProcCocoSink(output_dir, options, indent, label_mapping if mapping is None else None)
    images = [np.asarray(image) for image in colors]
    try:
        sink.begin(count, [PassLayout("colors", "uint8", images[0].shape)] if images else [], {}, {})
        for index in range(count):
            sink.write(index, {"colors": images[index], "instance_segmaps": np.asarray(instance_segmaps[index]),
                               "instance_attribute_maps": list(instance_attribute_maps[index])})
        sink.end()
        sink.finalize()
    except BaseException:
        sink.abort()
        raise
