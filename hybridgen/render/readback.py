"""What one label draw of one keypoint reads back from the raster view: the input of every raster pass."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class RasterOutput:
    """What one label draw of one keypoint reads back, all top-down (row 0 = image row v = 0).

    ``normal_depth`` is (H, W, 4) float32: unit normal xyz (camera or world axes) and camera z (metres);
    ``instance`` is (H, W) uint32, 0 where no surface was hit.
    """

    normal_depth: np.ndarray
    instance: np.ndarray
    ray_lengths: np.ndarray  # (H, W) float32 |(x/z, y/z, 1)| per pixel centre
    category_lut: np.ndarray  # int32 lookup: instance id -> category_id (0 -> 0)
    depth_background: float

    @property
    def hit(self) -> np.ndarray:
        return self.instance != 0
