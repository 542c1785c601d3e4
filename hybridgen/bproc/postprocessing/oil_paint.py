"""``bproc.postprocessing.oil_paint_filter``: the most frequent value of each pixel's square neighbourhood,
applied at edges only by default (to make rendered depth look like a real sensor's)."""
from __future__ import annotations

from typing import Any

import numpy as np

from .depth import is_image_list, trim_redundant_channels
from .opencv import require_cv2

__all__ = ["oil_paint_filter"]


def _neighbourhood(image: np.ndarray, filter_size: int) -> list[np.ndarray]:
    """The image and its shifted copies, one per offset (p, q) of a ``filter_size`` square window (p, q from
    ``-(filter_size // 2)``, rows outer, the (0, 0) offset first instead): copy (p, q) holds at (r, c) the
    pixel (r - p, c - q), 0 outside the image (BlenderProc's order)."""
    reach = filter_size // 2
    rows, cols = image.shape[:2]
    padding = [(reach, reach), (reach, reach)] + [(0, 0)] * (image.ndim - 2)
    padded = np.pad(image, padding)
    offsets = [(p, q) for p in range(-reach, filter_size - reach) for q in range(-reach, filter_size - reach)]
    shifted = [padded[reach - p:reach - p + rows, reach - q:reach - q + cols] for p, q in offsets if p or q]
    return [image] + shifted


def _edges(image: np.ndarray, high: float) -> np.ndarray:
    """Where OpenCV's Canny (thresholds 0 and ``high``) finds edges in the uint8 image."""
    cv2 = require_cv2("bproc.postprocessing.oil_paint_filter(edges_only=True)")
    return cv2.Canny(image, 0, high) > 0


def _filter_rgb(image: np.ndarray, filter_size: int, edges_only: bool) -> np.ndarray:
    """Per pixel, the neighbour (in :func:`_neighbourhood`'s order) whose mean intensity is the window's most
    frequent one; at Canny edges of the uint8 RGB image only when ``edges_only``."""
    from scipy import stats  # here: SciPy's stats cost ~0.2 s of import in every BlenderProc script's start

    neighbours = np.stack(_neighbourhood(image, filter_size))
    intensity = np.stack(_neighbourhood(np.sum(image, axis=2) / 3.0, filter_size), axis=2)
    mode = stats.mode(intensity, axis=2, keepdims=True).mode
    first = np.argmax(intensity == mode, axis=2)
    rows, cols = np.indices(first.shape)
    filtered = neighbours[first, rows, cols, :]
    if not edges_only:
        return filtered
    result = image.copy()
    edges = _edges(image, float(np.max(image)))
    result[edges] = filtered[edges]
    return result


def oil_paint_filter(image: Any, filter_size: int = 5, edges_only: bool = True, rgb: bool = False) -> Any:
    """The oil paint filter of one image or a list of images (a list back).

    Single-channel images (H x W, or H x W x 3 copies, trimmed first) get the most frequent value of each
    ``filter_size`` square window (zeros outside the image, the smallest value on a tie). With ``edges_only``
    only pixels on Canny edges of the image scaled to 0..255 change (infinite depth is clipped to the largest
    finite value first); this needs OpenCV. With ``rgb`` the image is RGB and each pixel takes the color of the
    window's pixel with the most frequent intensity. The given array is not changed (BlenderProc writes the
    edge pixels into it).
    """
    if rgb:
        if isinstance(image, list) or (hasattr(image, "shape") and len(image.shape) > 3):
            return [oil_paint_filter(element, filter_size, edges_only, rgb) for element in image]
        return _filter_rgb(np.asarray(image), filter_size, edges_only)
    image = trim_redundant_channels(image)
    if is_image_list(image):
        return [oil_paint_filter(element, filter_size, edges_only, rgb) for element in image]
    from scipy import stats

    filtered = stats.mode(np.dstack(_neighbourhood(image, filter_size)), axis=2, keepdims=False).mode
    if not edges_only:
        return filtered
    top = np.max(image) if np.max(image) != np.inf else np.unique(image)[-2]
    scaled = (np.minimum(image, top) / top) * 255.0
    as_bytes = np.uint8(scaled)
    result = np.array(image, copy=True)
    edges = _edges(as_bytes, float(np.max(as_bytes)))
    result[edges] = filtered[edges]
    return result
