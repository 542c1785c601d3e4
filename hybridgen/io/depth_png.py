"""Depth as a 16-bit PNG (BOP's ``depth/``, ``hybridgen extract``): value * depth_scale = millimetres, 0 = no
depth."""
from __future__ import annotations

import numpy as np


def depth_png_values(depth: np.ndarray, depth_scale: float, background: float = float("inf")
                     ) -> tuple[np.ndarray, int]:
    """uint16 image (value * ``depth_scale`` = mm) of ``depth`` in metres, and how many valid pixels were too
    far for 16 bits (written as 0, "no depth", like ``background``, non-finite and non-positive pixels)."""
    depth = np.asarray(depth, dtype=np.float64)
    valid = np.isfinite(depth) & (depth > 0)
    if np.isfinite(background):
        valid &= depth != background
    units = np.rint(np.where(valid, depth, 0.0) * (1000.0 / depth_scale))
    too_far = valid & (units > 65535)
    units[too_far] = 0
    return units.astype(np.uint16), int(too_far.sum())
