"""What one label draw of one keypoint reads back from the raster view: the input of every raster pass."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np


@dataclass
class RasterOutput:
    """What one label draw of one keypoint reads back, all top-down (row 0 = image row v = 0).

    Default targets: ``normal_depth`` is (H, W, 4) float32: unit normal xyz (camera or world axes) and camera z
    (metres); ``instance`` is (H, W) uint32, 0 where no surface was hit.

    Packed targets (:mod:`hybridgen.render.raster.label_targets`): ``normal_depth`` is None; ``depth_image`` is (H, W)
    float32 camera z with ``depth_background`` where nothing was hit; ``normal_codes`` (H, W, 2) uint16
    octahedral codes (None when normals were not drawn); ``instance`` and ``category`` (None unless drawn) are
    (H, W) in the narrowest unsigned type holding the scene's ids. Each is its own contiguous array.
    ``encoded``: output key -> the storage tag (:func:`~hybridgen.io.label_encoding.storage_tag`) in which
    every sink receiving that key stores it: such passes are handed on in that form.
    """

    normal_depth: np.ndarray | None
    instance: np.ndarray
    rays: Callable[[], np.ndarray]  # gives :attr:`ray_lengths` (the view's cache), asked only by passes that need it
    category_lut: np.ndarray  # int32 lookup: instance id -> category_id (0 -> 0)
    depth_background: float
    depth_image: np.ndarray | None = None
    normal_codes: np.ndarray | None = None
    category: np.ndarray | None = None
    encoded: dict[str, str] = field(default_factory=dict)  # key -> storage tag the sinks take it in

    @property
    def ray_lengths(self) -> np.ndarray:
        """(H, W) float32 ``|(x/z, y/z, 1)|`` per pixel centre: camera distance over z. Found when first asked
        (the denoiser's guides never ask: 0.03 s per 960x720 canvas saved)."""
        return self.rays()

    @property
    def hit(self) -> np.ndarray:
        return self.instance != 0

    @property
    def packed(self) -> bool:
        """Whether the draw wrote the packed targets."""
        return self.normal_depth is None

    @property
    def z(self) -> np.ndarray:
        """(H, W) float32 camera z where a surface was hit (other pixels: 0, or the depth background if packed)."""
        return self.depth_image if self.normal_depth is None else self.normal_depth[..., 3]
