"""Binary masks as COCO segmentations: RLE (compressed with pycocotools, or uncompressed as BOP writes it),
exact pixel-outline polygons, boxes and areas.

Coordinates are COCO's: pixel (u, v) covers the square [u, u+1] x [v, v+1] (our pixel centres, at integer
(u, v) in docs/conventions.md section 2, sit at (u + 0.5, v + 0.5) here). Boxes are ``[x, y, w, h]`` in whole pixels, as
BlenderProc and the BOP toolkit write them.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import SystemSetupError

PYCOCOTOOLS_HINT = ("RLE masks need pycocotools: `.venv/bin/pip install pycocotools` (or "
                    "`pip install 'hybridgen[coco]'`), or use mask_encoding_format: polygon")


def require_pycocotools() -> Any:
    """``pycocotools.mask``, or a SystemSetupError that says how to install it."""
    try:
        from pycocotools import mask as mask_utils
    except ImportError:
        raise SystemSetupError(PYCOCOTOOLS_HINT) from None
    return mask_utils


def bbox_of(mask: np.ndarray) -> list[int]:
    """``[x, y, w, h]`` of the True pixels (pixel indices, sizes in pixels); [-1, -1, -1, -1] when none."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return [-1, -1, -1, -1]
    return [int(cols[0]), int(rows[0]), int(cols[-1] - cols[0] + 1), int(rows[-1] - rows[0] + 1)]


def rle_compressed(mask: np.ndarray) -> dict[str, Any]:
    """COCO compressed RLE ``{"size": [h, w], "counts": str}`` made by pycocotools."""
    mask_utils = require_pycocotools()
    rle = mask_utils.encode(np.asfortranarray(mask, dtype=np.uint8))
    return {"size": [int(s) for s in rle["size"]], "counts": rle["counts"].decode("ascii")}


def rle_uncompressed(mask: np.ndarray) -> dict[str, Any]:
    """COCO uncompressed RLE ``{"counts": [...], "size": [h, w]}`` (column-major runs, starting with a
    background run), as the BOP toolkit writes it. Needs no pycocotools."""
    flat = np.asarray(mask, dtype=bool).ravel(order="F")
    counts: list[int] = []
    if flat.size:
        changes = np.flatnonzero(flat[1:] != flat[:-1]) + 1
        bounds = np.concatenate(([0], changes, [flat.size]))
        counts = np.diff(bounds).tolist()
        if flat[0]:
            counts.insert(0, 0)
    return {"counts": counts, "size": [int(mask.shape[0]), int(mask.shape[1])]}


# The four sides of a pixel as directed boundary edges, walked with the pixel (inside) on the right (x right,
# y down): walking direction, start corner relative to the pixel's top-left corner. Side k + 1 is side k
# turned right, side k + 3 turned left.
_SIDE_STEPS = np.array([(1, 0), (0, 1), (-1, 0), (0, -1)])  # top, right, bottom, left
_SIDE_STARTS = np.array([(0, 0), (1, 0), (1, 1), (0, 1)])


def _outline_walk(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Corner points (n, 2) of every outline loop, concatenated in loop order, and each loop's corner count.

    Every boundary edge (a pixel side with the pixel inside and its neighbour outside) gets its successor
    from the 2x2 pixels around its end corner: turn right if the pixel ahead is outside, else go straight if
    the pixel ahead-left is outside, else turn left (so corner-touching pixels stay apart). The successor map
    is a permutation whose cycles are the loops. Pointer jumping (array operations, log2 of the longest loop
    rounds) finds each loop's smallest start corner (its root) and every edge's place after it.
    """
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    height, width = m.shape
    plane = height * width
    inside = m.ravel()
    step = _SIDE_STEPS[:, 1] * width + _SIDE_STEPS[:, 0]  # flat offset of each side's walking direction
    inward = np.roll(step, -1)  # ... and of its right-hand (inward) normal
    # boundary edge id = side * plane + flat pixel index (padded grid); the outside neighbour is pixel - inward
    pixels = np.flatnonzero(inside)
    ids = np.concatenate([side * plane + pixels[~inside[pixels - inward[side]]] for side in range(4)])
    count = ids.size
    if count == 0:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    side, pixel = np.divmod(ids, plane)
    ahead = pixel + step[side]
    ahead_left = ahead - inward[side]
    right_turn = ~inside[ahead]
    straight = ~right_turn & ~inside[ahead_left]
    next_side = np.where(right_turn, (side + 1) % 4, np.where(straight, side, (side + 3) % 4))
    next_pixel = np.where(right_turn, pixel, np.where(straight, ahead, ahead_left))
    index = np.empty(4 * plane, np.int64)
    index[ids] = np.arange(count)
    successor = index[next_side * plane + next_pixel]
    # start corners (x, y) in unpadded pixel coordinates: padded pixel (py, px) is pixel (px - 1, py - 1)
    py, px = np.divmod(pixel, width)
    start_x = px - 1 + _SIDE_STARTS[side, 0]
    start_y = py - 1 + _SIDE_STARTS[side, 1]
    key = start_x * (height + 1) + start_y  # order of corners: x, then y (unique per loop edge start)
    # each loop's smallest key: min over 2^k successors after k rounds, until 2^k covers every loop
    smallest, nxt, span = key.copy(), successor, 1
    while span < count:
        smallest = np.minimum(smallest, smallest[nxt])
        nxt = nxt[nxt]
        span *= 2
    roots = np.flatnonzero(key == smallest)  # the loop's smallest corner has exactly one outgoing edge
    # distance from each edge forward to its root (the root absorbs), and the root it reaches
    nxt = successor.copy()
    nxt[roots] = roots
    dist = np.ones(count, np.int64)
    dist[roots] = 0
    while True:
        jumped = nxt[nxt]
        if np.array_equal(jumped, nxt):
            break
        dist += dist[nxt]
        nxt = jumped
    root_rank = np.empty(count, np.int64)
    root_rank[roots[np.argsort(key[roots])]] = np.arange(roots.size)  # loops in order of their smallest corner
    loop = root_rank[nxt]
    length = np.bincount(loop, minlength=roots.size)
    offset = np.concatenate(([0], np.cumsum(length)[:-1]))
    slot = offset[loop] + (length[loop] - dist) % length[loop]  # root first, then along the loop
    walked_side = np.empty(count, np.int64)
    walked_side[slot] = side
    points = np.empty((count, 2), np.int64)
    points[slot, 0], points[slot, 1] = start_x, start_y
    previous = np.roll(walked_side, 1)
    previous[offset] = walked_side[offset + length - 1]  # a loop's first edge follows its last
    corner = walked_side != previous  # a start point where the direction changes
    corners_per_loop = np.add.reduceat(corner.astype(np.int64), offset)
    return points[corner], corners_per_loop


def outline_loops(mask: np.ndarray) -> list[np.ndarray]:
    """Every boundary loop of ``mask`` along pixel edges, as (k, 2) arrays of corner points (x, y).

    Outer boundaries run clockwise on screen (positive shoelace area with y down), holes the other way.
    Pixels touching only at a corner belong to separate loops (4-connectivity). Only corners are listed
    (no collinear points); loops are closed implicitly. Each loop starts at its smallest corner (x, then y),
    and loops come in that order.
    """
    points, counts = _outline_walk(mask)
    return np.split(points, np.cumsum(counts)[:-1]) if counts.size else []


def signed_area(loop: np.ndarray) -> float:
    """Shoelace area of a closed loop of (x, y) points; positive for outer loops of :func:`outline_loops`."""
    x, y = loop[:, 0].astype(np.float64), loop[:, 1].astype(np.float64)
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) / 2.0


def mask_to_polygons(mask: np.ndarray) -> list[list[float]]:
    """COCO polygons ``[[x0, y0, x1, y1, ...], ...]`` tracing the outer pixel outlines of ``mask`` exactly.

    COCO polygons cannot describe holes (several polygons are a union), so holes are filled: use RLE for
    masks with holes.
    """
    points, counts = _outline_walk(mask)
    if counts.size == 0:
        return []
    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    following = np.arange(1, len(points) + 1)  # index of each corner's successor within its loop
    following[starts + counts - 1] = starts
    x, y = points[:, 0], points[:, 1]
    twice_area = np.add.reduceat(x * y[following] - x[following] * y, starts)  # shoelace, per loop
    flat = points.astype(np.float64).ravel().tolist()
    return [flat[2 * start:2 * (start + n)] for start, n, area in zip(starts.tolist(), counts.tolist(),
                                                                      twice_area.tolist()) if n >= 3 and area > 0]
