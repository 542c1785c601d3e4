"""``bproc.postprocessing.remove_segmap_noise``: stray values of interpolated segmentation maps."""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["remove_segmap_noise"]

_RARE = 100
"""A value (after scaling) seen at most this often in an image is taken as interpolation noise."""


def _noisy_indices(image: np.ndarray) -> np.ndarray:
    """Indices (rows of ``np.argwhere``, channel included) of the entries whose value, scaled by 37 / 65536 and
    truncated as BlenderProc does for 16-bit maps, occurs at most 100 times in the image."""
    scaled = (image * 37 / 65536).astype(np.int32)
    values, counts = np.unique(scaled, return_counts=True)
    return np.argwhere(np.isin(scaled, values[counts <= _RARE]))


def remove_segmap_noise(image: Any) -> Any:
    """The segmentation map(s) (H x W x C, e.g. class ids read from an EXR) with each noisy pixel set, in every
    channel, to the smallest value among its up to 8 neighbours (BlenderProc's rule; pixels are visited in
    row-major order and see their neighbours' new values). Works in place on the given array and returns it,
    as BlenderProc does; a list or a stack of more than three axes gives a list."""
    if isinstance(image, list) or (hasattr(image, "shape") and len(image.shape) > 3):
        return [remove_segmap_noise(element) for element in image]
    rows, cols = image.shape[:2]
    for index in _noisy_indices(image):
        row, col = int(index[0]), int(index[1])
        window = image[max(0, row - 1):min(rows, row + 2), max(0, col - 1):min(cols, col + 2)]
        centre = (row - max(0, row - 1), col - max(0, col - 1))
        neighbours = np.delete(window.reshape(window.shape[0] * window.shape[1], -1),
                               centre[0] * window.shape[1] + centre[1], axis=0)
        if neighbours.size:
            image[row, col] = neighbours.min()
    return image
