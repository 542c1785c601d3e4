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


# Directions in image coordinates (x right, y down) and their right turn for the outline walk.
_RIGHT_TURN = {(1, 0): (0, 1), (0, 1): (-1, 0), (-1, 0): (0, -1), (0, -1): (1, 0)}


def outline_loops(mask: np.ndarray) -> list[np.ndarray]:
    """Every boundary loop of ``mask`` along pixel edges, as (k, 2) arrays of corner points (x, y).

    Outer boundaries run clockwise on screen (positive shoelace area with y down), holes the other way.
    Pixels touching only at a corner belong to separate loops (4-connectivity). Only corners are listed
    (no collinear points); loops are closed implicitly.
    """
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    inside = m[1:-1, 1:-1]
    edges: dict[tuple[int, int], list[tuple[int, int]]] = {}
    # (boundary pixels, start corner relative to the pixel's top-left corner, step) per side; interior on the right
    sides = ((inside & ~m[:-2, 1:-1], (0, 0), (1, 0)),   # top edge, walking +x
             (inside & ~m[1:-1, 2:], (1, 0), (0, 1)),    # right edge, walking +y
             (inside & ~m[2:, 1:-1], (1, 1), (-1, 0)),   # bottom edge, walking -x
             (inside & ~m[1:-1, :-2], (0, 1), (0, -1)))  # left edge, walking -y
    for boundary, (dx, dy), step in sides:
        for y, x in zip(*np.nonzero(boundary)):
            edges.setdefault((int(x) + dx, int(y) + dy), []).append(step)

    def take(point: tuple[int, int], step: tuple[int, int]) -> None:
        outgoing = edges[point]
        outgoing.remove(step)
        if not outgoing:
            del edges[point]

    def choose(heading: tuple[int, int], options: list[tuple[int, int]]) -> tuple[int, int]:
        # right turn first, then straight on, then left: corner-touching pixels stay in separate loops
        right = _RIGHT_TURN[heading]
        for step in (right, heading, (-right[0], -right[1])):
            if step in options:
                return step
        raise AssertionError("pixel outline is not closed")  # cannot happen for edges of a pixel set

    loops = []
    while edges:
        start = min(edges)
        first = edges[start][0]
        take(start, first)
        corners, heading = [start], first
        point = (start[0] + first[0], start[1] + first[1])
        while True:
            options = list(edges.get(point, ()))
            if point == start:
                options.append(first)
            step = choose(heading, options)
            if point == start and step == first:
                break
            take(point, step)
            if step != heading:
                corners.append(point)
            heading = step
            point = (point[0] + step[0], point[1] + step[1])
        if heading == first:  # the start lies on a straight run: not a corner
            corners = corners[1:]
        loops.append(np.array(corners, dtype=np.int64))
    return loops


def signed_area(loop: np.ndarray) -> float:
    """Shoelace area of a closed loop of (x, y) points; positive for outer loops of :func:`outline_loops`."""
    x, y = loop[:, 0].astype(np.float64), loop[:, 1].astype(np.float64)
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) / 2.0


def mask_to_polygons(mask: np.ndarray) -> list[list[float]]:
    """COCO polygons ``[[x0, y0, x1, y1, ...], ...]`` tracing the outer pixel outlines of ``mask`` exactly.

    COCO polygons cannot describe holes (several polygons are a union), so holes are filled: use RLE for
    masks with holes.
    """
    polygons = []
    for loop in outline_loops(mask):
        if len(loop) >= 3 and signed_area(loop) > 0:
            polygons.append(loop.astype(np.float64).ravel().tolist())
    return polygons
