"""``bproc.utility.generate_random_pattern_img`` (BlenderProc's PatternUtility): a transparent RGBA image with
white dots spread over a grid of cells, e.g. a projector pattern for active stereo.

The image is split into cells of ``m_w = int(width // sqrt(n_points))`` by ``m_h = int(height // sqrt(n_points))``
pixels (float floor division, as BlenderProc computes it); the cells are visited column of cells by column of
cells (``i`` over ``width // m_w`` outer, ``j`` over ``height // m_h`` inner), and each draws one dot centre from
Python's ``random`` module: first ``x = random.randint(i m_w, (i + 1) m_w - 1)``, then
``y = random.randint(j m_h, (j + 1) m_h - 1)``. The same seed therefore gives BlenderProc's dots (``hybridgen
run`` seeds ``random`` as BlenderProc does).

BlenderProc draws each dot with OpenCV's ``cv2.circle(img, (x, y), 1, (255, 255, 255, 255), -1)``. Measured with
opencv 4.10 (tests/bproc/test_random_pattern.py stores the measurement): that filled circle of radius 1 sets
exactly five pixels, the centre and its four edge neighbours (a plus sign), clipped at the image border. Here
that stencil is drawn with NumPy, so OpenCV is not needed.
"""
from __future__ import annotations

import random

import numpy as np

from ..errors import InputError

CIRCLE_RADIUS_1 = ((0, 0), (-1, 0), (1, 0), (0, -1), (0, 1))
"""(dy, dx) pixel offsets that OpenCV's filled ``cv2.circle`` of radius 1 sets around its integer centre."""


def dot_centres(width: int, height: int, n_points: int) -> list[tuple[int, int]]:
    """The (x, y) pixel centres BlenderProc draws, in its order, taking the values from ``random``."""
    if int(n_points) < 1:
        raise InputError(f"n_points must be at least 1, got {n_points}")
    cell_w = int(int(width) // np.sqrt(int(n_points)))
    cell_h = int(int(height) // np.sqrt(int(n_points)))
    if cell_w < 1 or cell_h < 1:
        raise InputError(f"a {width}x{height} image has no room for {n_points} points: each needs a cell of at "
                         f"least 1x1 pixels (width and height at least sqrt(n_points))")
    centres = []
    for i in range(int(width) // cell_w):
        for j in range(int(height) // cell_h):
            x = random.randint(i * cell_w, (i + 1) * cell_w - 1)
            y = random.randint(j * cell_h, (j + 1) * cell_h - 1)
            centres.append((x, y))
    return centres


def draw_dots(width: int, height: int, centres: list[tuple[int, int]]) -> np.ndarray:
    """(height, width, 4) uint8 RGBA: 0 everywhere except white opaque (255, 255, 255, 255) where OpenCV's filled
    radius-1 circle at an (x, y) of ``centres`` would set a pixel (:data:`CIRCLE_RADIUS_1`, clipped)."""
    image = np.zeros((int(height), int(width), 4), dtype=np.uint8)
    points = np.array(centres, dtype=np.int64).reshape(-1, 2)
    for dy, dx in CIRCLE_RADIUS_1:
        rows, cols = points[:, 1] + dy, points[:, 0] + dx
        inside = (rows >= 0) & (rows < image.shape[0]) & (cols >= 0) & (cols < image.shape[1])
        image[rows[inside], cols[inside]] = 255
    return image


def generate_random_pattern_img(width: int, height: int, n_points: int) -> np.ndarray:
    """BlenderProc's random dot pattern: (height, width, 4) uint8 RGBA, transparent black with a white plus-shaped
    dot of radius 1 px at each of :func:`dot_centres` (one per grid cell, about ``n_points``)."""
    return draw_dots(width, height, dot_centres(width, height, n_points))
