"""Per-object passes of one keypoint for dataset writers (BOP, COCO): amodal masks, pixel counts and visible
fractions, and 2D boxes - made on the render side from one set of single-object silhouettes
(:mod:`hybridgen.render.raster.silhouettes`), so that writers need no GL and no geometry.

Each value is a dict by instance id over every object of the scene - or only those the asking sinks read
(``wanted_objects()``, :mod:`hybridgen.render.passes`) - (objects behind the near or beyond the far plane
have empty masks and no pixels; objects outside the image may count pixels outside it).
Counts and boxes follow the BOP toolkit: ``px_count_all`` counts the full silhouette also outside the image;
boxes are ``[x, y, x_max - x, y_max - y]`` (:func:`~hybridgen.render.raster.silhouettes.toolkit_box`), ``bbox_obj``
may extend past the image, :data:`~hybridgen.render.raster.silhouettes.NO_BOX` when there are no pixels.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .silhouettes import NO_BOX, toolkit_box

if TYPE_CHECKING:
    from .keypoint_frame import KeypointFrame


def amodal_masks(frame: "KeypointFrame", key: str) -> dict[int, np.ndarray]:
    """``{instance id: (H, W) bool}``: each object's full silhouette inside the image."""
    return {idx: s.mask for idx, s in frame.silhouettes().items()}


def _visible_counts(frame: "KeypointFrame") -> np.ndarray:
    return frame.shared("visible_counts", lambda: np.bincount(
        frame.raw.instance.ravel(), minlength=max((o.instance_id for o in frame.scene.objects), default=0) + 1))


def visible_fractions(frame: "KeypointFrame", key: str) -> dict[int, dict[str, Any]]:
    """``{instance id: {px_count_all, px_count_visib, visib_fract}}``: pixels of the full silhouette (also
    outside the image), visible pixels (the instance map's), and visible / all (0.0 when all is 0)."""
    counts = _visible_counts(frame)
    out = {}
    for idx, silhouette in frame.silhouettes().items():
        visib = int(counts[idx])
        total = silhouette.px_count_all
        out[idx] = {"px_count_all": total, "px_count_visib": visib, "visib_fract": visib / total if total else 0.0}
    return out


def object_boxes(frame: "KeypointFrame", key: str) -> dict[int, dict[str, list[int]]]:
    """``{instance id: {bbox_obj, bbox_visib}}``: toolkit boxes of the full silhouette (image pixel
    coordinates, may extend past the image) and of the visible pixels."""
    instance = frame.raw.instance
    out = {}
    for idx, silhouette in frame.silhouettes().items():
        ys, xs = np.nonzero(instance == idx)
        out[idx] = {"bbox_obj": list(silhouette.bbox_obj), "bbox_visib": toolkit_box(xs, ys) if xs.size
                    else list(NO_BOX)}
    return out
