"""COCO instance annotations (BlenderProc's ``CocoAnnotationsWriter``): ``images/`` plus ``coco_annotations.json``.

Per keypoint one image ``images/<prefix><image id, 6 digits>.png`` (or ``.jpg``; with ``image_names=
"blenderproc"`` BlenderProc's ``rgb_<image id, 4 digits>.png`` next to the JSON, whose ``file_name`` is
``<folder name>/rgb_0000.png`` as BlenderProc writes it) of the chosen key
(``colors`` by default) and one annotation per visible instance with a non-zero ``category_id``:
``segmentation`` (compressed RLE via pycocotools, or exact pixel-outline polygons), ``bbox`` ``[x, y, w, h]``
(pixel indices, w/h in pixels), ``area`` (pixels), ``iscrowd`` 0. Masks are the exact instance map
(``instance_segmaps``); categories come from the objects' ``category_id``, named by an optional label
mapping (else by the first object of that category in view, as BlenderProc does). Objects whose
``supercategory`` (or ``bop_dataset_name``) attribute differs from a requested ``supercategory`` are left out.

With ``append`` an existing ``coco_annotations.json`` is extended: image ids continue after the highest one
there, annotation ids after the highest annotation id, categories are merged by id. Images are staged
under temporary names and the JSON file is replaced atomically only when the run commits; nothing is
written or overwritten if rendering fails. No timestamps are written, so a run is reproducible byte for byte.
"""
from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..config.options import checked_options, option
from ..errors import InputError
from .atomic import prepare_output_dir
from .bounded_read import MAX_TABLE_BYTES, read_bounded_text
from .coco_content import annotation, coco_file, load_coco_file
from ..render.passes import hint
from .frame_sink import PassLayout
from .image_files import StagedFiles, color_format_option, jpeg_bytes, jpg_quality_option, png_bytes, write_file
from .mask_encoding import bbox_of, mask_to_polygons, require_pycocotools, rle_compressed, rle_uncompressed
from .output_lock import hold_output_lock

ANNOTATIONS_FILE = "coco_annotations.json"
MASK_ENCODINGS = ("rle", "polygon")
IMAGE_NAMES = ("hybridgen", "blenderproc")
"""hybridgen: images/<prefix><id:06d>; blenderproc: rgb_<id:04d> next to coco_annotations.json."""
DEFAULT_SUPERCATEGORY = "coco_annotations"

NEEDED_KEYS = {key: hint(key) for key in ("instance_segmaps", "instance_attribute_maps")}


def image_key_hint(key: str) -> str:
    """How to make the image key ``key``."""
    if key == "colors":
        return hint(key)
    return f"make a renderer write '{key}', or set rgb_output_key to a key it writes"


def load_label_mapping(value: Mapping[Any, Any] | str | Path | None) -> dict[int, str] | None:
    """``{category_id: name}`` from a mapping, or from a CSV file with ``id`` and ``name`` columns (BlenderProc's
    ``LabelIdMapping`` format)."""
    if value is None:
        return None
    if isinstance(value, Mapping):
        items = list(value.items())
        where = "label_mapping"
    else:
        path = Path(value)
        text = read_bounded_text(path, MAX_TABLE_BYTES, "label mapping", latin1_fallback=True)
        rows = list(csv.DictReader(io.StringIO(text, newline="")))
        if not rows or "id" not in rows[0] or "name" not in rows[0]:
            raise InputError(f"label mapping '{path}' needs a CSV header with 'id' and 'name' columns")
        items = [(row["id"], row["name"]) for row in rows]
        where = str(path)
    mapping: dict[int, str] = {}
    for key, name in items:
        try:
            category = int(str(key).strip())
        except ValueError:
            raise InputError(f"{where}: category id {key!r} is not an integer") from None
        mapping[category] = str(name)
    return mapping


def _prefix_check(value: str) -> str | None:
    return f"must be a plain file name prefix (no '/'), got {value!r}" if "/" in value or "\\" in value else None


@dataclass(frozen=True)
class CocoOptions:
    """The options of a COCO annotations writer, declared once: writer.CocoAnnotationsWriter's parameters
    are these (:func:`~hybridgen.config.options.option_params`)."""

    image_key: str = option("colors", "str", "uint8 image key written to images/", key="rgb_output_key")
    mask_encoding: str = option("rle", "str", "rle: compressed RLE (pycocotools, exact); polygon: exact pixel "
                                "outlines (holes filled)", choices=MASK_ENCODINGS, key="mask_encoding_format")
    color_file_format: str = color_format_option("image file format")
    jpg_quality: int = jpg_quality_option()
    supercategory: str = option(DEFAULT_SUPERCATEGORY, "str", "only objects whose 'supercategory' (or "
                                "'bop_dataset_name') attribute is this; the default takes every object")
    label_mapping: Any = option(None, "dict|path|null", "category names: {category_id: name} or a CSV file with "
                                "id,name columns; default: the name of the first object of the category")
    append: bool = option(False, "bool", "extend an existing coco_annotations.json: image and annotation ids "
                          "continue after its highest ones", key="append_to_existing_output")
    file_prefix: str = option("", "str", "prefix of the image file names", check=_prefix_check)
    image_names: str = option("hybridgen", "str", "hybridgen: images/<prefix><id:06d>.png; blenderproc: "
                              "BlenderProc's <prefix>rgb_<id:04d>.png next to coco_annotations.json, file_name "
                              "'<folder>/rgb_0000.png' (the default for configs in BlenderProc's form)",
                              choices=IMAGE_NAMES)


class CocoWriter:
    """Frame sink writing COCO annotations to ``output_dir`` (see the module documentation).

    Needs per keypoint the image key and ``instance_segmaps`` + ``instance_attribute_maps``, from one or
    several renderers. :meth:`finalize` commits, :meth:`abort` drops everything staged.

    Subclasses may change the JSON's form (BlenderProc 2's ``write_coco_annotations``,
    :mod:`hybridgen.bproc.coco_writer`): ``compressed_rle``, ``indent``, :meth:`_category_name`, :meth:`_content`.
    """

    compressed_rle = True
    """RLE masks as pycocotools' compressed strings; False: uncompressed run lists (no pycocotools needed)."""
    indent: int | str | None = None
    """The JSON file's indent (``json.dumps``); None: compact."""

    def __init__(self, output_dir: str | Path, options: CocoOptions | None = None, **given: Any) -> None:
        """``options`` (validated where they were made), or the options ``given`` by name (validated here)."""
        if options is not None and given:
            raise TypeError("give CocoWriter either options or single options, not both")
        opts = options if options is not None else checked_options(CocoOptions, **given)
        if opts.mask_encoding == "rle" and self.compressed_rle:
            require_pycocotools()
        self.label_mapping = load_label_mapping(opts.label_mapping)
        self.output_dir = prepare_output_dir(Path(output_dir))
        self.path = self.output_dir / ANNOTATIONS_FILE
        if self.path.exists() and not self.path.is_file():
            raise InputError(f"'{self.path}' exists and is not a file")
        self._unlock = hold_output_lock(self.output_dir)  # ids and image names stay ours until finalize/abort
        try:
            self.existing = load_coco_file(self.path) if opts.append and self.path.exists() else None
        except BaseException:
            self._unlock()
            raise
        self.image_offset = 1 + max((e["id"] for e in self.existing["images"]), default=-1) if self.existing else 0
        self.image_key, self.mask_encoding = opts.image_key, opts.mask_encoding
        self.extension = ".png" if opts.color_file_format == "PNG" else ".jpg"
        self.jpg_quality, self.supercategory = int(opts.jpg_quality), opts.supercategory
        self.file_prefix = opts.file_prefix
        self.count = 0
        self.images: dict[int, dict[str, Any]] = {}
        self.annotations: dict[int, list[dict[str, Any]]] = {}
        self.categories: dict[int, dict[str, Any]] = {}
        self._pending: dict[int, dict[str, Any]] = {}
        self._staged = StagedFiles()
        self.blenderproc_names = opts.image_names == "blenderproc"
        self._image_dir = self.output_dir if self.blenderproc_names else self.output_dir / "images"

    # ------------------------------------------------------------------ FrameSink
    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        """Check one renderer's keys (no stereo; the image key must be a uint8 image)."""
        if any(layout.stereo for layout in layouts):
            raise InputError("writer.CocoAnnotationsWriter does not support stereo renders (as in BlenderProc); "
                             "render left and right as separate keypoints instead")
        self.count = max(self.count, n_keypoints)
        for layout in layouts:
            if layout.key == self.image_key and (layout.dtype != "uint8" or len(layout.shape) not in (2, 3)):
                raise InputError(f"COCO images need a uint8 image key; '{self.image_key}' is {layout.dtype} "
                                 f"{layout.shape}")

    def write(self, index: int, values: dict[str, Any]) -> None:
        """Stage keypoint ``index``'s image and compute its annotations as soon as their inputs are there."""
        if self.image_key in values:
            self._write_image(index, np.asarray(values[self.image_key]))
        pending = self._pending.setdefault(index, {})
        for key in NEEDED_KEYS:
            if key in values:
                pending[key] = values[key]
        if all(key in pending for key in NEEDED_KEYS):
            self.annotations[index] = self._annotate(self.image_id(index), np.asarray(pending["instance_segmaps"]),
                                                     pending["instance_attribute_maps"])
            del self._pending[index]

    def end(self) -> None:
        """Nothing is buffered beyond what the next renderer completes."""

    # ------------------------------------------------------------------ commit
    def missing_keys(self) -> list[str]:
        """Keys some keypoint never received."""
        indices = range(self.count)
        missing = [self.image_key] if any(i not in self.images for i in indices) else []
        for key in NEEDED_KEYS:
            if any(i not in self.annotations and key not in self._pending.get(i, {}) for i in indices):
                missing.append(key)
        return missing

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        """Rename the staged images and write ``coco_annotations.json`` (merged with the existing one);
        returns ``[the JSON file]``. Scene ``records`` and run ``attributes`` are not part of COCO."""
        if self.count == 0:
            raise InputError("no keypoint was rendered before the COCO writer")
        missing = self.missing_keys()
        if missing:
            hints = {image_key_hint(self.image_key) if k == self.image_key else NEEDED_KEYS[k] for k in missing}
            raise InputError(f"COCO annotations need {missing} for every keypoint: " + "; ".join(sorted(hints)))
        content = self._content()
        self._staged.commit()
        write_file(self.path, json.dumps(content, indent=self.indent).encode("utf-8"), durable=True)
        self._unlock()
        return [self.path]

    def abort(self) -> None:
        """Delete every staged image; the annotations file is untouched."""
        self._staged.discard()
        self._unlock()

    # ------------------------------------------------------------------ internals
    def image_id(self, index: int) -> int:
        return self.image_offset + index

    def _write_image(self, index: int, image: np.ndarray) -> None:
        self._staged.make_dir(self._image_dir)
        if self.blenderproc_names:  # BlenderProc: rgb_%04d, file_name relative to the folder above the JSON's
            name = f"{self.file_prefix}rgb_{self.image_id(index):04d}{self.extension}"
            file_name = f"{self.output_dir.name}/{name}"
        else:
            name = f"{self.file_prefix}{self.image_id(index):06d}{self.extension}"
            file_name = f"images/{name}"
        rgb = image if image.ndim == 3 else np.repeat(image[..., None], 3, axis=2)
        data = png_bytes(image) if self.extension == ".png" else jpeg_bytes(rgb[..., :3], self.jpg_quality)
        self._staged.add(self._image_dir / name, data)
        self.images[index] = {"id": self.image_id(index), "file_name": file_name,
                              "width": int(image.shape[1]), "height": int(image.shape[0])}

    def _included(self, record: dict[str, Any]) -> bool:
        own = record.get("bop_dataset_name", record.get("supercategory", DEFAULT_SUPERCATEGORY))
        return self.supercategory in (own, DEFAULT_SUPERCATEGORY)

    def _category(self, record: dict[str, Any]) -> int | None:
        """The record's category id (registering the category), or None if it is not annotated."""
        category = record.get("category_id")
        if category is None:
            raise InputError(f"writer.CocoAnnotationsWriter: object '{record.get('name')}' (instance "
                             f"{record.get('idx')}) has no category_id: COCO annotations need one (set category_id "
                             "on its loader or main.Initializer default_category_id)")
        category = int(category)
        if category == 0 or not self._included(record):
            return None
        if category not in self.categories:
            name = self._category_name(record, category)
            supercategory = record.get("bop_dataset_name", record.get("supercategory", DEFAULT_SUPERCATEGORY))
            self.categories[category] = {"id": category, "name": name, "supercategory": supercategory}
        return category

    def _category_name(self, record: dict[str, Any], category: int) -> Any:
        """The name of ``category``, first seen on the object of ``record``: the label mapping's, else the
        object's ``name``, else the id as text."""
        if self.label_mapping is not None:
            if category not in self.label_mapping:
                raise InputError(f"label_mapping has no name for category_id {category} (object "
                                 f"'{record.get('name')}')")
            return self.label_mapping[category]
        return str(record.get("name", category))

    def _segmentation(self, mask: np.ndarray) -> Any:
        """The COCO segmentation of one instance's mask in this writer's encoding."""
        if self.mask_encoding == "polygon":
            return mask_to_polygons(mask)
        return rle_compressed(mask) if self.compressed_rle else rle_uncompressed(mask)

    def _annotate(self, image_id: int, instance: np.ndarray, records: list[dict[str, Any]]) -> list[dict[str, Any]]:
        """Annotations (without ids) of one keypoint's visible instances, by instance id."""
        if isinstance(records, (str, bytes)):
            records = json.loads(records)
        by_id = {int(r["idx"]): r for r in records}
        counts = np.bincount(instance.ravel(), minlength=1)
        out = []
        for idx in np.flatnonzero(counts):
            if idx == 0:
                continue
            record = by_id.get(int(idx))
            if record is None:
                raise InputError(f"instance {idx} is in the instance map but not in instance_attribute_maps")
            category = self._category(record)
            if category is None:
                continue
            mask = instance == idx
            out.append(annotation(image_id, category, int(counts[idx]), bbox_of(mask), self._segmentation(mask),
                                  width=mask.shape[1], height=mask.shape[0]))
        return out

    def _content(self) -> dict[str, Any]:
        info = {"description": self.supercategory, "version": "1.0", "contributor": "hybridgen"}
        return coco_file(self.existing, info, [c for _, c in sorted(self.categories.items())],
                         [self.images[i] for i in range(self.count)],
                         [a for index in range(self.count) for a in self.annotations[index]])
