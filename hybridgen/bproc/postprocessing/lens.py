"""``bproc.postprocessing.apply_lens_distortion``: resample undistorted renders into the distorted image that
``bproc.camera.set_lens_distortion`` planned (it returns the mapping and enlarges the render resolution)."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

__all__ = ["apply_lens_distortion"]


def _distort(image: np.ndarray, mapping_coords: np.ndarray, width: int, height: int, order: int) -> np.ndarray:
    """One image (H x W or H x W x C) resampled at ``mapping_coords`` (2 x N: rows then columns in the
    undistorted render, pixel centres at integers, N = width * height in row-major order) with a spline of
    ``order`` (2, or 0 for the nearest pixel), edge pixels repeated outside; the input's dtype back (uint8
    clipped to 0..255 first)."""
    from scipy.ndimage import map_coordinates  # here: SciPy's ndimage costs ~0.1 s of import in every script's start

    data = image.astype(np.float32)
    planes = [data] if image.ndim == 2 else [data[:, :, channel] for channel in range(image.shape[2])]
    distorted = np.stack([map_coordinates(plane, mapping_coords, order=order, mode="nearest").reshape(height, width)
                          for plane in planes], axis=2).astype(np.float64)
    if image.dtype == np.uint8:
        distorted = np.clip(distorted, 0, 255)
    distorted = distorted.astype(image.dtype)
    return distorted[:, :, 0] if image.ndim == 2 else distorted


def apply_lens_distortion(image: Any, mapping_coords: Optional[np.ndarray] = None, orig_res_x: Optional[int] = None,
                          orig_res_y: Optional[int] = None, use_interpolation: bool = True) -> Any:
    """The image (or each image of a list) distorted to the ``orig_res_x`` x ``orig_res_y`` pixel resolution
    asked for before ``bproc.camera.set_lens_distortion`` enlarged the render, by sampling the render at
    ``mapping_coords`` (what that call returned): quadratic spline interpolation, or the nearest pixel when
    ``use_interpolation`` is false.
    """
    if mapping_coords is None or orig_res_x is None or orig_res_y is None:
        raise ValueError("bproc.postprocessing.apply_lens_distortion needs mapping_coords, orig_res_x and "
                         "orig_res_y: pass what bproc.camera.set_lens_distortion returned")
    order = 2 if use_interpolation else 0
    if isinstance(image, list):
        return [_distort(np.asarray(element), mapping_coords, int(orig_res_x), int(orig_res_y), order)
                for element in image]
    if isinstance(image, np.ndarray):
        return _distort(image, mapping_coords, int(orig_res_x), int(orig_res_y), order)
    raise TypeError(f"bproc.postprocessing.apply_lens_distortion takes an array or a list of arrays, "
                    f"got {type(image).__name__}")
