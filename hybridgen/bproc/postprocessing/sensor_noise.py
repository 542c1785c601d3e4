"""Depth-sensor noise of ``bproc.postprocessing``: ``add_gaussian_shifts`` and ``add_kinect_azure_noise``.

BlenderProc computes these with OpenCV 4.10 (the version it pins); hybridgen computes the same numbers with
NumPy and SciPy, so they need no OpenCV: bilinear resampling on OpenCV's 1/32-pixel grid with zeros outside
the image (``cv2.remap``, ``INTER_LINEAR``), 3x3 minimum / maximum filters (``cv2.erode`` / ``cv2.dilate``) and
OpenCV's 15-bit RGB-to-grey weights. Random numbers come from ``np.random`` in BlenderProc's order. Depth is in
metres, image axes are rows x columns.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from .depth import is_image_list

__all__ = ["add_gaussian_shifts", "add_kinect_azure_noise"]

_SUBPIXELS = 32
"""OpenCV 4.10's remap rounds sample positions to 1/32 pixel (``INTER_TAB_SIZE``)."""


def _pixels(image: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``image[rows, cols]``, 0 where the index is outside the image (OpenCV's ``BORDER_CONSTANT``)."""
    height, width = image.shape
    inside = (rows >= 0) & (rows < height) & (cols >= 0) & (cols < width)
    values = image[np.clip(rows, 0, height - 1), np.clip(cols, 0, width - 1)]
    return np.where(inside, values, np.zeros((), dtype=image.dtype))


def remap_linear(image: np.ndarray, map_x: np.ndarray, map_y: np.ndarray) -> np.ndarray:
    """``cv2.remap(image, map_x, map_y, cv2.INTER_LINEAR)`` of OpenCV 4.10 for a float H x W image: output pixel
    (r, c) is the bilinear sample at column ``map_x[r, c]``, row ``map_y[r, c]`` (pixel centres at integers),
    the position rounded to 1/32 pixel, pixels outside the image 0, weights and sums in the image's type."""
    fixed_x = np.rint(np.asarray(map_x, dtype=np.float32) * _SUBPIXELS).astype(np.int64)
    fixed_y = np.rint(np.asarray(map_y, dtype=np.float32) * _SUBPIXELS).astype(np.int64)
    x0, y0 = fixed_x // _SUBPIXELS, fixed_y // _SUBPIXELS
    ax = ((fixed_x % _SUBPIXELS) / _SUBPIXELS).astype(np.float32)
    ay = ((fixed_y % _SUBPIXELS) / _SUBPIXELS).astype(np.float32)
    one = np.float32(1.0)
    return (_pixels(image, y0, x0) * ((one - ay) * (one - ax)) + _pixels(image, y0, x0 + 1) * ((one - ay) * ax)
            + _pixels(image, y0 + 1, x0) * (ay * (one - ax)) + _pixels(image, y0 + 1, x0 + 1) * (ay * ax)
            ).astype(image.dtype)


def add_gaussian_shifts(image: Any, std: float = 0.5) -> Any:
    """The H x W depth image(s) resampled at positions shifted by normal noise of ``std`` pixels per axis: one
    ``np.random.normal(0, std, (H, W, 2))`` draw per image (column shift, row shift), positions clamped to
    ``[0, W]`` x ``[0, H]``, bilinear with zeros outside (:func:`remap_linear`). A list or stack gives a list."""
    if is_image_list(image):
        return [add_gaussian_shifts(element, std=std) for element in image]
    rows, cols = image.shape
    shifts = np.random.normal(0, std, size=(rows, cols, 2)).astype(np.float32)
    xs, ys = np.meshgrid(np.arange(cols, dtype=np.float32), np.arange(rows, dtype=np.float32))
    map_x = np.minimum(np.maximum(xs + shifts[:, :, 0], 0.0), cols)
    map_y = np.minimum(np.maximum(ys + shifts[:, :, 1], 0.0), rows)
    return remap_linear(np.asarray(image), map_x, map_y)


def rgb_to_grey(color: np.ndarray) -> np.ndarray:
    """``cv2.cvtColor(color, cv2.COLOR_RGB2GRAY)``: 0.299 R + 0.587 G + 0.114 B; for uint8 OpenCV's 15-bit fixed
    point (9798, 19235, 3735, rounded), for float images in float32."""
    if color.dtype == np.uint8:
        channels = color.astype(np.int64)
        weighted = channels[..., 0] * 9798 + channels[..., 1] * 19235 + channels[..., 2] * 3735
        return ((weighted + (1 << 14)) >> 15).astype(np.uint8)
    channels = color.astype(np.float32)
    return channels[..., 0] * np.float32(0.299) + channels[..., 1] * np.float32(0.587) \
        + channels[..., 2] * np.float32(0.114)


def add_kinect_azure_noise(depth: Any, color: Optional[Any] = None, missing_depth_darkness_thres: int = 15) -> Any:
    """Depth image(s) (m) with the Azure Kinect's noise (Tölgyessy et al., Sensors 21(2):413, 2021), as in
    BlenderProc: :func:`add_gaussian_shifts` with 0.25 px; plus normal noise of 0.5 mm + 1 mm per metre beyond
    0.5 m (one ``np.random.normal`` per pixel, after the shifts' draw); 0 (missing) where the 3x3 neighbourhood
    spans more than 0.8 m; and 0 where the RGB ``color`` image is darker than ``missing_depth_darkness_thres``
    (grey value, uint8 scale). A list or stack of depth images (with as many colors) gives a list.
    """
    if is_image_list(depth):
        colors = [None] * len(depth) if color is None else color
        if len(colors) != len(depth):
            raise ValueError(f"add_kinect_azure_noise: {len(depth)} depth images but {len(colors)} color images")
        return [add_kinect_azure_noise(d, c, missing_depth_darkness_thres) for d, c in zip(depth, colors)]
    from scipy import ndimage  # here: SciPy's ndimage costs ~0.1 s of import in every script's start

    noisy = add_gaussian_shifts(depth, 0.25)
    noisy += (5 / 10000 + np.maximum((noisy - 0.5) * 1 / 1000, 0)) * np.random.normal(size=noisy.shape)
    spread = ndimage.maximum_filter(noisy, size=3, mode="nearest") - ndimage.minimum_filter(noisy, size=3,
                                                                                            mode="nearest")
    noisy[abs(spread) > 0.8] = 0
    if color is not None:
        noisy[rgb_to_grey(np.asarray(color)) < missing_depth_darkness_thres] = 0
    return noisy
