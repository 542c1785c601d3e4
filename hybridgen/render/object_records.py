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
border, width = max - min).
"""
from __future__ import annotations

from itertools import product
from typing import Any

import numpy as np

from ..scene.camera import Intrinsics
from .passes import RasterOutput
from .raster import RasterView


def box_of(mask: np.ndarray) -> list[int]:
    """[x, y, w, h] of the True pixels of ``mask`` ([-1, -1, 0, 0] when none)."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return [-1, -1, 0, 0]
    return [int(cols[0]), int(rows[0]), int(cols[-1] - cols[0] + 1), int(rows[-1] - rows[0] + 1)]


def _corners(bounds: np.ndarray) -> np.ndarray:
    return np.array([[bounds[i, 0], bounds[j, 1], bounds[k, 2]] for i, j, k in product((0, 1), repeat=3)])


def _may_be_in_view(corners_cam: np.ndarray, intr: Intrinsics) -> bool:
    """Conservative: False only if the box is certainly outside the view frustum."""
    z = corners_cam[:, 2]
    if (z < intr.clip_start).all() or (z > intr.clip_end).all():
        return False
    if (z <= intr.clip_start).any():
        return True  # crosses the near plane: projection is unreliable, draw it
    u = intr.K[0, 0] * corners_cam[:, 0] / z + intr.K[0, 2]
    v = intr.K[1, 1] * corners_cam[:, 1] / z + intr.K[1, 2]
    return not (u.max() < -0.5 or u.min() > intr.width - 0.5 or v.max() < -0.5 or v.min() > intr.height - 0.5)


def amodal_mask(view: RasterView, cam2world: np.ndarray, instance_id: int,
                intrinsics: Intrinsics | None = None) -> np.ndarray:
    """Boolean (H, W) silhouette of one object drawn alone at ``cam2world``."""
    others = frozenset(o.instance_id for o in view.scene.objects if o.instance_id != instance_id)
    return view.render_raw(cam2world, intrinsics, hidden=others).instance == instance_id


def object_records(view: RasterView, raw: RasterOutput, cam2world: np.ndarray) -> list[dict[str, Any]]:
    """The records of every object in view at ``cam2world`` (``raw``: that keypoint's readback)."""
    intr = view.scene.camera.intrinsics
    world2cam = np.linalg.inv(cam2world)
    visible_counts = np.bincount(raw.instance.ravel(), minlength=len(view.scene.objects) + 1)
    records = []
    for obj in view.scene.objects:
        obj2cam = world2cam @ obj.local2world
        corners = _corners(obj.bounds_local) @ obj2cam[:3, :3].T + obj2cam[:3, 3]
        if not _may_be_in_view(corners, intr):
            continue
        full = amodal_mask(view, cam2world, obj.instance_id)
        count_all = int(full.sum())
        if count_all == 0:
            continue
        count_visib = int(visible_counts[obj.instance_id]) if obj.instance_id < len(visible_counts) else 0
        records.append({
            "idx": obj.instance_id, "name": obj.name, "category_id": obj.category_id,
            "obj2cam": obj2cam.tolist(), "bbox3d_cam": corners.tolist(),
            "bbox_visib": box_of(raw.instance == obj.instance_id), "bbox_obj": box_of(full),
            "px_count_visib": count_visib, "px_count_all": count_all, "visib_fract": count_visib / count_all,
        })
    return records
