"""Colors for previews (``hybridgen vis``, ``hybridgen gallery``): viridis, the Middlebury optical-flow color
wheel, and a stable palette for segmentation ids. All return uint8 RGB arrays of shape ``(..., 3)``.
"""
from __future__ import annotations

import numpy as np

from .viridis_data import VIRIDIS

_VIRIDIS = np.asarray(VIRIDIS, dtype=np.float64)
# matplotlib's byte lookup table of a listed colormap: entries * 255, truncated
VIRIDIS_BYTES = (_VIRIDIS * 255).astype(np.uint8)


def viridis(t: np.ndarray) -> np.ndarray:
    """viridis of ``t`` in [0, 1] (clipped; NaN -> 0), as matplotlib's ``cm.viridis(t, bytes=True)``: entry
    ``floor(t * 256)`` of the 256-entry table (t = 1 -> the last entry)."""
    values = np.nan_to_num(np.asarray(t, dtype=np.float64), nan=0.0)
    index = np.clip(np.floor(values * 256), 0, 255).astype(np.intp)
    return VIRIDIS_BYTES[index]


def _wheel() -> np.ndarray:
    """The Middlebury flow color wheel (Baker et al., "A Database and Evaluation Methodology for Optical
    Flow", IJCV 2011): 55 hues through red, yellow, green, cyan, blue, magenta, in 15/6/4/11/13/6 steps."""
    segments = ((15, (255, 0, 0), (255, 255, 0)), (6, (255, 255, 0), (0, 255, 0)), (4, (0, 255, 0), (0, 255, 255)),
                (11, (0, 255, 255), (0, 0, 255)), (13, (0, 0, 255), (255, 0, 255)), (6, (255, 0, 255), (255, 0, 0)))
    rows = []
    for steps, start, end in segments:
        ramp = np.floor(255 * np.arange(steps) / steps)  # the channel that changes moves in floor(255 i / n) steps
        for i in range(steps):
            rows.append([s if s == e else (ramp[i] if e > s else 255 - ramp[i]) for s, e in zip(start, end)])
    return np.asarray(rows, dtype=np.float64)


FLOW_WHEEL = _wheel()


def flow_to_color(flow: np.ndarray, max_radius: float | None = None) -> np.ndarray:
    """Optical flow ``(..., 2)`` in pixels (u right, v down) in the Middlebury color coding: the hue is the
    direction on :data:`FLOW_WHEEL` (right red, down yellow, left cyan, up blue-violet), saturation grows
    with the magnitude relative to ``max_radius`` (default: the largest finite magnitude), zero flow is
    white, and flow beyond ``max_radius`` is darkened to 75 %. Non-finite flow is black."""
    flow = np.asarray(flow, dtype=np.float64)
    finite = np.isfinite(flow).all(axis=-1)
    u = np.where(finite, flow[..., 0], 0.0)
    v = np.where(finite, flow[..., 1], 0.0)
    radius = np.hypot(u, v)
    if max_radius is None:
        max_radius = float(radius.max()) if radius.size else 0.0
    scale = max_radius if max_radius > 0 else 1.0
    u, v, radius = u / scale, v / scale, radius / scale
    count = len(FLOW_WHEEL)
    angle = np.arctan2(-v, -u) / np.pi  # in [-1, 1]
    position = (angle + 1) / 2 * (count - 1)
    k0 = np.floor(position).astype(np.intp)
    k1 = (k0 + 1) % count
    fraction = (position - k0)[..., None]
    color = ((1 - fraction) * FLOW_WHEEL[k0] + fraction * FLOW_WHEEL[k1]) / 255.0
    inside = (radius <= 1)[..., None]
    color = np.where(inside, 1 - radius[..., None] * (1 - color), color * 0.75)
    rgb = np.floor(255 * color).astype(np.uint8)
    rgb[~finite] = 0
    return rgb


def id_colors(ids: np.ndarray) -> np.ndarray:
    """A distinct, stable color per integer id (golden-ratio hues, fixed saturation); id 0 (background) is
    black. The same id has the same color in every image, tile and legend."""
    values = np.asarray(ids).astype(np.int64)
    hue = (values * 0.618033988749895) % 1.0
    h6 = hue * 6
    channels = np.stack([np.abs(h6 - 3) - 1, 2 - np.abs(h6 - 2), 2 - np.abs(h6 - 4)], -1).clip(0, 1)
    rgb = (0.25 + 0.7 * channels) * 255
    rgb[values == 0] = 0
    return rgb.astype(np.uint8)
