"""One keypoint's value of one key -> an RGB preview image and its legend (for ``vis`` and ``gallery``).

- ``depth``, ``distance`` and other float maps: viridis over the finite range (legend: the scale in metres),
  pixels without a value (``inf``, NaN) black.
- Integer id maps (``*_segmaps``): one stable color per id (:func:`~hybridgen.io.colormaps.id_colors`),
  background 0 black; the legend names each id from the keypoint's ``instance_attribute_maps`` (instance
  ids -> object name and category; category/attribute values -> the objects having them).
- ``*_flow``: the Middlebury color wheel (legend: the largest magnitude in pixels).
- ``normals``: ``(n + 1) / 2`` as RGB; ``nocs``: as stored; ``albedo``/``colors_hdr`` (linear): sRGB;
  uint8 colors as stored; uint8 masks (``*_occluded``) white where 1.
Stereo values (a leading axis of 2) are split by :func:`eyes` first. Which key is which comes from the
pass catalogue (:mod:`hybridgen.render.passes`: ``show``, stored names recognised by their patterns).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..render.passes import RECORDS, recognise
from ..render.tonemap import to_srgb8
from .colormaps import flow_to_color, id_colors, viridis

NOT_IMAGES = tuple(key for key, kind in RECORDS.items() if kind == "camera")


def _show(key: str) -> str:
    entry = recognise(key)
    return entry.show if entry is not None else ""


@dataclass
class Legend:
    """What a preview's colors mean: a value scale (``low``..``high`` ``unit``) and/or labelled id colors."""

    title: str
    low: float | None = None
    high: float | None = None
    unit: str = ""
    entries: list[tuple[int, tuple[int, int, int], str]] = field(default_factory=list)  # (id, rgb, label)


@dataclass
class Preview:
    """An RGB image (H, W, 3) uint8 and its legend (None when colors are the data)."""

    image: np.ndarray
    legend: Legend | None = None


def is_image(key: str, value: Any) -> bool:
    """Whether a sample's ``value`` of ``key`` is an image (H, W[, C]) of one eye."""
    return isinstance(value, np.ndarray) and value.ndim in (2, 3) and key not in NOT_IMAGES and min(value.shape[:2]) > 1


def eyes(key: str, value: Any, stereo: bool) -> list[tuple[str, Any]]:
    """``[(title, value)]``: one entry, or ``key (left)``/``key (right)`` for a stereo pair."""
    if stereo and isinstance(value, np.ndarray) and value.ndim >= 3 and value.shape[0] == 2 and key not in NOT_IMAGES:
        return [(f"{key} (left)", value[0]), (f"{key} (right)", value[1])]
    return [(key, value)]


def eye_visible(visible: Any, eye: int, stereo: bool) -> list[dict[str, Any]] | None:
    """The ``instance_attribute_maps`` of eye ``eye``: stereo runs store a [left, right] pair per keypoint."""
    if stereo and isinstance(visible, list) and len(visible) == 2 and isinstance(visible[0], list):
        return visible[eye]
    return visible


def _names(visible: list[dict[str, Any]], attribute: str) -> dict[int, list[dict[str, Any]]]:
    """Visible objects grouped by their value of ``attribute`` (``idx`` for instance ids)."""
    groups: dict[int, list[dict[str, Any]]] = {}
    for obj in visible:
        value = obj.get(attribute)
        if isinstance(value, (int, float)) and not isinstance(value, bool) and float(value).is_integer():
            groups.setdefault(int(value), []).append(obj)
    return groups


def id_legend(key: str, ids: np.ndarray, visible: list[dict[str, Any]] | None) -> Legend:
    """The legend of an id map: every id in it, its color and what it is."""
    entry = recognise(key)
    attribute = ("idx" if key.startswith("instance") else key[: -len("_segmaps")]
                 if entry is not None and entry.key == "<attribute>_segmaps" else key)
    groups = _names(visible or [], attribute)
    entries = []
    present = [int(i) for i in np.unique(ids)]
    colors = id_colors(np.asarray(present))
    for value, rgb in zip(present, colors):
        if value == 0:
            label = "background"
        elif attribute == "idx" and value in groups:
            obj = groups[value][0]
            label = f"{obj.get('name', '?')} (category {obj.get('category_id', '?')})"
        elif value in groups:
            label = ", ".join(str(o.get("name", "?")) for o in groups[value])
        else:
            label = "?"
        entries.append((value, (int(rgb[0]), int(rgb[1]), int(rgb[2])), label))
    return Legend(f"{key}: id -> {'object' if attribute == 'idx' else 'objects'}", entries=entries)


def preview(key: str, value: np.ndarray, visible: list[dict[str, Any]] | None = None) -> Preview:
    """The preview of one image value (see the module docs); ``visible`` is the keypoint's
    ``instance_attribute_maps`` for naming segmentation ids."""
    if value.ndim == 3 and value.shape[-1] == 2 and np.issubdtype(value.dtype, np.floating):
        finite = np.isfinite(value).all(axis=-1)
        largest = float(np.hypot(value[..., 0], value[..., 1])[finite].max()) if finite.any() else 0.0
        return Preview(flow_to_color(value), Legend(f"{key}: color wheel", 0.0, largest, "px"))
    if value.ndim == 3 and value.shape[-1] in (3, 4) and value.dtype == np.uint8:
        return Preview(np.ascontiguousarray(value[..., :3]))
    if value.ndim == 3 and np.issubdtype(value.dtype, np.floating):
        rgb = np.nan_to_num(value[..., :3].astype(np.float32))
        if _show(key) == "half_unit":
            return Preview(np.rint(np.clip((rgb + 1) / 2, 0, 1) * 255).astype(np.uint8))
        if _show(key) == "srgb":
            return Preview(to_srgb8(np.clip(rgb, 0, None)))
        return Preview(np.rint(np.clip(rgb, 0, 1) * 255).astype(np.uint8))
    if value.ndim == 2 and value.dtype == np.uint8:
        return Preview(np.repeat((np.clip(value, 0, 1) * 255).astype(np.uint8)[..., None], 3, axis=2))
    if value.ndim == 2 and np.issubdtype(value.dtype, np.integer):
        return Preview(id_colors(value), id_legend(key, value, visible))
    if value.ndim == 2 and np.issubdtype(value.dtype, np.floating):
        return metric_preview(key, value)
    raise ValueError(f"no preview for '{key}' ({value.dtype}, shape {value.shape})")


def metric_preview(key: str, values: np.ndarray, unit: str = "m") -> Preview:
    """viridis over the finite range of ``values``; non-finite pixels black."""
    finite = np.isfinite(values)
    low, high = (float(values[finite].min()), float(values[finite].max())) if finite.any() else (0.0, 0.0)
    scaled = (values.astype(np.float64) - low) / (high - low if high > low else 1.0)
    rgb = viridis(np.where(finite, scaled, 0.0))
    rgb[~finite] = 0
    return Preview(rgb, Legend(f"{key} [{unit}]", low, high, unit))
