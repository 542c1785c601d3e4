"""Per-keypoint records of every object in view: pose relative to the camera, 2D and 3D boxes, pixel counts.

One record per object whose full (amodal) silhouette covers at least one pixel centre::

    idx, name, category_id,
    obj2cam          4x4, object local -> OpenCV camera (m; includes the object's scale)
    bbox3d_cam       8 x 3 corners of the object's local bounding box in camera coordinates (m)
    bbox_visib       [x, y, w, h] of the visible pixels (pixel indices; w, h in pixels), or [-1, -1, 0, 0]
    bbox_obj         [x, y, w, h] of the amodal silhouette (the object rendered alone)
    px_count_visib   visible pixels; px_count_all: amodal pixels; visib_fract = visib / all

Amodal silhouettes come from drawing each object alone in the raster view - exact, not thresholded depth.
Boxes and counts are of pixels inside the image, and box widths count pixels (max - min + 1); the BOP
writer (:mod:`hybridgen.io.bop_writer`) follows the BOP toolkit instead (amodal counts beyond the image
border, width = max - min), taking them from the render-side passes of :mod:`hybridgen.render.raster.object_passes`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ...io.mask_encoding import bbox_of

if TYPE_CHECKING:
    from .keypoint_frame import KeypointFrame

RECORD_NO_BOX = [-1, -1, 0, 0]


def box_of(mask: np.ndarray) -> list[int]:
    """[x, y, w, h] of the True pixels of ``mask`` (widths count pixels; [-1, -1, 0, 0] when none)."""
    return bbox_of(mask) if mask.any() else list(RECORD_NO_BOX)


def object_records(frame: "KeypointFrame") -> list[dict[str, Any]]:
    """The records of every object in view at ``frame``'s keypoint (amodal silhouettes on the image canvas)."""
    instance = frame.raw.instance
    visible_counts = np.bincount(instance.ravel(), minlength=len(frame.scene.objects) + 1)
    records = []
    for obj in frame.scene.objects:
        where = frame.placements()[obj.instance_id]
        if not where.may_be_in_image:
            continue
        full = frame.image_silhouette(obj)
        count_all = int(full.sum())
        if count_all == 0:
            continue
        count_visib = int(visible_counts[obj.instance_id]) if obj.instance_id < len(visible_counts) else 0
        records.append({
            "idx": obj.instance_id, "name": obj.name, "category_id": obj.category_id,
            "obj2cam": where.obj2cam.tolist(), "bbox3d_cam": where.corners.tolist(),
            "bbox_visib": box_of(instance == obj.instance_id), "bbox_obj": box_of(full),
            "px_count_visib": count_visib, "px_count_all": count_all, "visib_fract": count_visib / count_all,
        })
    return records
