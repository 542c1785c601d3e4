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

from ...scene.camera import Intrinsics
from ...scene.mesh_object import MeshObject
from .raster_view import RasterView

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


def region(corners: np.ndarray, intr: Intrinsics) -> tuple[int, int, int, int] | None:
    """``(x, y, width, height)`` of the canvas pixels whose centres may lie in the projection of ``corners``
    (camera coordinates, all in front of the near plane), with a pixel of margin; None: the whole canvas.
    The silhouette of a body inside a box lies in the convex hull of the box's projected corners."""
    z = corners[:, 2]
    if (z <= intr.clip_start).any():
        return None
    u = intr.K[0, 0] * corners[:, 0] / z + intr.K[0, 2]
    v = intr.K[1, 1] * corners[:, 1] / z + intr.K[1, 2]
    x0, y0 = max(int(np.floor(u.min())) - 1, 0), max(int(np.floor(v.min())) - 1, 0)
    x1, y1 = min(int(np.ceil(u.max())) + 2, intr.width), min(int(np.ceil(v.max())) + 2, intr.height)
    return (x0, y0, max(x1 - x0, 1), max(y1 - y0, 1)) if x0 < intr.width and y0 < intr.height else (0, 0, 1, 1)


def draw_part(view: RasterView, obj: MeshObject, cam2world: np.ndarray, intr: Intrinsics,
              corners: np.ndarray) -> tuple[np.ndarray, int, int]:
    """``(mask, x, y)``: the boolean silhouette of ``obj`` drawn alone at ``cam2world`` on a canvas of
    intrinsics ``intr``, in the rectangle at column ``x``, row ``y`` where its box ``corners`` (camera
    coordinates) project - the canvas outside it holds none of the silhouette."""
    others = frozenset(o.instance_id for o in view.scene.objects if o.instance_id != obj.instance_id)
    area = region(corners, intr) or (0, 0, intr.width, intr.height)
    return view.render_ids(cam2world, intr, hidden=others, region=area) == obj.instance_id, area[0], area[1]


def draw_alone(view: RasterView, obj: MeshObject, cam2world: np.ndarray, intr: Intrinsics,
               corners: np.ndarray) -> np.ndarray:
    """The (H, W) boolean silhouette of ``obj`` on the whole canvas (see :func:`draw_part`)."""
    part, x, y = draw_part(view, obj, cam2world, intr, corners)
    full = np.zeros((intr.height, intr.width), dtype=bool)
    full[y:y + part.shape[0], x:x + part.shape[1]] = part
    return full


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
        mask = on_image()
        ys, xs = np.nonzero(mask)
        return Silhouette(np.ascontiguousarray(mask), int(xs.size), toolkit_box(xs, ys))
    part, x, y = draw_part(view, obj, cam2world, wide_intrinsics(intr), where.corners)
    ys, xs = np.nonzero(part)
    mask = np.zeros((height, width), dtype=bool)  # the image is the centre of the wide canvas
    x0, y0 = max(x, width), max(y, height)
    x1, y1 = min(x + part.shape[1], 2 * width), min(y + part.shape[0], 2 * height)
    if x1 > x0 and y1 > y0:
        mask[y0 - height:y1 - height, x0 - width:x1 - width] = part[y0 - y:y1 - y, x0 - x:x1 - x]
    return Silhouette(mask, int(xs.size), toolkit_box(xs + x - width, ys + y - height))
