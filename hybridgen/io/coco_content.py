"""The COCO annotations file (https://cocodataset.org/#format-data), assembled in one place for every writer
that makes one: ``coco_annotations.json`` (:mod:`hybridgen.io.coco_writer`) and BOP's per-chunk
``scene_gt_coco.json`` (:mod:`hybridgen.io.bop_writer`).

Annotation ids are assigned here, continuing after the highest id of an existing file; categories are merged
by id (existing ones kept as they are); images and annotations are appended. Key order is fixed (``id``,
``image_id``, ``category_id``, ``iscrowd``, ``area``, ``bbox``, ``segmentation``, ``width``, ``height``, then
extras), so the same inputs give the same bytes.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..errors import InputError


def annotation(image_id: int, category_id: int, area: int, bbox: list[int], segmentation: Any, width: int,
               height: int, **extra: Any) -> dict[str, Any]:
    """One annotation without its ``id`` (assigned by :func:`coco_file`). ``area`` in pixels, ``bbox``
    ``[x, y, w, h]`` in pixels, ``segmentation`` RLE or polygons of a ``width`` x ``height`` image."""
    return {"image_id": int(image_id), "category_id": int(category_id), "iscrowd": 0, "area": int(area),
            "bbox": bbox, "segmentation": segmentation, "width": int(width), "height": int(height), **extra}


def coco_file(existing: dict[str, Any] | None, info: dict[str, Any], categories: list[dict[str, Any]],
              images: list[dict[str, Any]], annotations: list[dict[str, Any]]) -> dict[str, Any]:
    """The file's content: ``existing`` (or a new file with ``info``) plus ``categories`` whose id it does
    not know yet, ``images`` and ``annotations`` (from :func:`annotation`; ids assigned here)."""
    content = dict(existing) if existing is not None else {"info": info, "licenses": [], "categories": [],
                                                            "images": [], "annotations": []}
    known = {c.get("id") for c in content["categories"]}
    content["categories"] = content["categories"] + [c for c in categories if c["id"] not in known]
    next_id = 1 + max((a.get("id", 0) for a in content["annotations"]), default=0)
    content["images"] = content["images"] + images
    content["annotations"] = content["annotations"] + [{"id": next_id + i, **a} for i, a in enumerate(annotations)]
    return content


def coco_problem(content: Any) -> str | None:
    """Why ``content`` is not a COCO annotations file that can be appended to (None when it is one)."""
    if not isinstance(content, dict):
        return "it is not a JSON object"
    for section in ("images", "annotations", "categories"):
        entries = content.get(section)
        if not isinstance(entries, list) or not all(isinstance(e, dict) and isinstance(e.get("id"), int)
                                                    for e in entries):
            return f"'{section}' is not a list of entries with integer ids"
    return None


def load_coco_file(path: Path) -> dict[str, Any]:
    """A COCO annotations file to append to, checked enough that appending cannot corrupt it."""
    try:
        content = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read '{path}' to append to it: {exc}") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"cannot append to '{path}': it is not valid JSON ({exc.msg} at line {exc.lineno}, "
                         f"column {exc.colno}); fix or remove it, or set append_to_existing_output: false") from None
    problem = coco_problem(content)
    if problem:
        raise InputError(f"cannot append to '{path}': {problem}; fix or remove it, or set "
                         "append_to_existing_output: false")
    return content
