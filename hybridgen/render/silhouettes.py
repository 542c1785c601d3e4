"""Single-object silhouettes: each object drawn alone in the raster view (exact at pixel centres), and the
view-frustum test that decides whether and on which canvas to draw it.

Two canvases, both with the image's pixel centres:

- ``image``: the image itself - the object's full (amodal) silhouette inside the image;
- ``wide``: three times the image size with the image in its centre, so that pixels of the silhouette
  outside the image are counted too (the BOP toolkit's ``px_count_all``). Objects whose bounding box
  projects inside the image, or images too large for a 3x canvas, are drawn on ``image`` instead.

Boxes come in two conventions: :func:`toolkit_box` (the BOP toolkit's ``[x, y, x_max - x, y_max - y]``) and
:func:`~hybridgen.io.mask_encoding.bbox_of` (COCO's, widths counting pixels).
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from typing import Callable

import numpy as np

from ..scene.camera import Intrinsics
from ..scene.mesh_object import MeshObject
from .raster import RasterView

MAX_CANVAS = 16384  # px per side the raster view accepts
NO_BOX = [-1, -1, -1, -1]


def box_corners(bounds: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3) of an axis-aligned box ``bounds`` (2, 3), x slowest."""
    return np.array([[bounds[i, 0], bounds[j, 1], bounds[k, 2]] for i, j, k in product((0, 1), repeat=3)])


def toolkit_box(xs: np.ndarray, ys: np.ndarray) -> list[int]:
    """The BOP toolkit's ``calc_2d_bbox`` of pixel coordinates: ``[x_min, y_min, x_max - x_min, y_max - y_min]``
    (:data:`NO_BOX` when there are none)."""
    if xs.size == 0:
        return list(NO_BOX)
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min()), int(ys.max() - ys.min())]


@dataclass(frozen=True)
class Placement:
    """Where an object's local bounding box lies relative to the view: its corners in OpenCV camera
    coordinates (m), whether all of them are behind the near or beyond the far plane (``clipped``), whether
    the box projects inside the image (``inside``; False when a corner is not in front of the near plane),
    and whether it certainly projects outside the image (``beyond``)."""

    obj2cam: np.ndarray
    corners: np.ndarray
    clipped: bool
    inside: bool
    beyond: bool

    @property
    def may_be_in_image(self) -> bool:
        return not (self.clipped or self.beyond)


def placement(obj: MeshObject, world2cam: np.ndarray, intr: Intrinsics) -> Placement:
    """The :class:`Placement` of ``obj`` for a camera at ``world2cam`` (4x4, OpenCV axes)."""
    obj2cam = world2cam @ obj.local2world
    corners = box_corners(obj.bounds_local) @ obj2cam[:3, :3].T + obj2cam[:3, 3]
    z = corners[:, 2]
    clipped = bool((z <= intr.clip_start).all() or (z >= intr.clip_end).all())
    inside = beyond = False
    if not clipped and (z > intr.clip_start).all():
        u = intr.K[0, 0] * corners[:, 0] / z + intr.K[0, 2]
        v = intr.K[1, 1] * corners[:, 1] / z + intr.K[1, 2]
        inside = bool(u.min() >= -0.5 and v.min() >= -0.5 and u.max() <= intr.width - 0.5
                      and v.max() <= intr.height - 0.5)
        beyond = bool(u.max() < -0.5 or u.min() > intr.width - 0.5 or v.max() < -0.5 or v.min() > intr.height - 0.5)
    return Placement(obj2cam, corners, clipped, inside, beyond)


def wide_intrinsics(intr: Intrinsics) -> Intrinsics:
    """The ``wide`` canvas: three times the image, the image in its centre (the same pixel centres)."""
    K = intr.K.copy()
    K[0, 2] += intr.width
    K[1, 2] += intr.height
    return Intrinsics(K, 3 * intr.width, 3 * intr.height, intr.clip_start, intr.clip_end)


def draw_alone(view: RasterView, obj: MeshObject, cam2world: np.ndarray, intr: Intrinsics) -> np.ndarray:
    """Boolean silhouette of ``obj`` drawn alone at ``cam2world`` on a canvas of intrinsics ``intr``."""
    others = frozenset(o.instance_id for o in view.scene.objects if o.instance_id != obj.instance_id)
    return view.render_raw(cam2world, intr, hidden=others).instance == obj.instance_id


@dataclass(frozen=True)
class Silhouette:
    """An object's full silhouette at one keypoint: ``mask`` (H, W) bool inside the image, ``px_count_all``
    its pixels including those outside the image, ``bbox_obj`` the toolkit box of all of them in image pixel
    coordinates (may extend past the image; :data:`NO_BOX` when there are none)."""

    mask: np.ndarray
    px_count_all: int
    bbox_obj: list[int]


def full_silhouette(view: RasterView, obj: MeshObject, cam2world: np.ndarray, where: Placement,
                    on_image: Callable[[], np.ndarray]) -> Silhouette:
    """The :class:`Silhouette` of ``obj``, counting pixels outside the image on the ``wide`` canvas;
    ``on_image()`` gives its silhouette on the ``image`` canvas (drawn once per keypoint by the caller)."""
    intr = view.scene.camera.intrinsics
    width, height = intr.width, intr.height
    if where.clipped:
        return Silhouette(np.zeros((height, width), dtype=bool), 0, list(NO_BOX))
    if where.inside or 3 * max(width, height) > MAX_CANVAS:
        full = on_image()
        mask, dx, dy = full, 0, 0
    else:
        full = draw_alone(view, obj, cam2world, wide_intrinsics(intr))
        mask, dx, dy = full[height:2 * height, width:2 * width], width, height
    ys, xs = np.nonzero(full)
    return Silhouette(np.ascontiguousarray(mask), int(xs.size), toolkit_box(xs - dx, ys - dy))
