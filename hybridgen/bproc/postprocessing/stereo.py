"""``bproc.postprocessing.stereo_global_matching``: depth from a rendered stereo pair by OpenCV's semi-global
block matching (Hirschmüller 2008), as BlenderProc computes it. Needs OpenCV (its contrib modules for the
WLS disparity filter).

Disparity is in pixels (the left image's column minus the right image's), depth in metres:
``depth = baseline * fx / disparity``.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from .opencv import require_cv2
from .scene_state import camera_K, distance_range_end, stereo_baseline

__all__ = ["stereo_global_matching"]

_CALL = "bproc.postprocessing.stereo_global_matching"


def _matchers(cv2: Any, window_size: int, num_disparities: int, min_disparity: int) -> Any:
    """BlenderProc's SGBM left matcher: block size 5, smoothness penalties 8 and 32 x 3 x window_size^2,
    uniqueness 15, no speckle filter, full 8-path (HH) mode."""
    return cv2.StereoSGBM_create(minDisparity=min_disparity, numDisparities=num_disparities, blockSize=5,
                                 P1=8 * 3 * window_size ** 2, P2=32 * 3 * window_size ** 2, disp12MaxDiff=-1,
                                 uniquenessRatio=15, speckleWindowSize=0, speckleRange=2, preFilterCap=63,
                                 mode=cv2.StereoSGBM_MODE_HH)


def _fill_in_fast(cv2: Any, depth: np.ndarray, max_depth: float) -> np.ndarray:
    """Depth completion by morphology (Ku et al. 2018's fast fill, bilateral variant): invert valid depths
    (> 0.1 m) against ``max_depth``, dilate 5x5, close 5x5, fill holes from a 7x7 dilation, median 5, bilateral
    (5, 1.5, 2.0), invert back."""
    full_5, full_7 = np.ones((5, 5), np.uint8), np.ones((7, 7), np.uint8)
    valid = depth > 0.1
    depth[valid] = max_depth - depth[valid]
    depth = cv2.morphologyEx(cv2.dilate(depth, full_5), cv2.MORPH_CLOSE, full_5)
    empty = depth < 0.1
    depth[empty] = cv2.dilate(depth, full_7)[empty]
    depth = cv2.bilateralFilter(cv2.medianBlur(depth, 5), 5, 1.5, 2.0)
    valid = depth > 0.1
    depth[valid] = max_depth - depth[valid]
    return depth


def _match_pair(cv2: Any, left: np.ndarray, right: np.ndarray, baseline: float, depth_max: float,
                focal_length: float, options: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(depth in m, disparity as OpenCV gives it: 16 x pixels, or the WLS-filtered map scaled to 0..255)."""
    matcher = _matchers(cv2, options["window_size"], options["num_disparities"], options["min_disparity"])
    disparity = matcher.compute(left, right)
    if options["disparity_filter"]:
        wls = cv2.ximgproc.createDisparityWLSFilter(matcher_left=matcher)
        wls.setLambda(80000)
        wls.setSigmaColor(1.2)
        right_disparity = cv2.ximgproc.createRightMatcher(matcher).compute(right, left)
        filtered = wls.filter(disparity, left, None, right_disparity).astype(np.float32)
        disparity = cv2.normalize(src=filtered, dst=filtered, beta=0, alpha=255, norm_type=cv2.NORM_MINMAX)
    with np.errstate(divide="ignore"):
        depth = (1.0 / (np.float32(np.copy(disparity)) / 16.0)) * baseline * focal_length
    depth[depth > depth_max] = depth_max
    depth[depth < 0] = 0.0
    if options["depth_completion"]:
        depth = _fill_in_fast(cv2, depth, depth_max)
    return depth, disparity


def stereo_global_matching(color_images: list[np.ndarray], depth_max: Optional[float] = None, window_size: int = 7,
                           num_disparities: int = 32, min_disparity: int = 0, disparity_filter: bool = True,
                           depth_completion: bool = True, *, baseline: Optional[float] = None,
                           K: Optional[Any] = None) -> tuple[list[np.ndarray], list[np.ndarray]]:  # noqa: N803
    """Per frame (each entry ``[2, H, W, 3]`` uint8: left, right), depth (m) and disparity from semi-global
    matching: ``(depth_frames, disparity_frames)``.

    ``depth_max`` (m) clips the depth; by default the distance pass's range end, as in BlenderProc.
    ``window_size`` (odd) sets the smoothness penalties, ``num_disparities`` (> 0, a multiple of 16) and
    ``min_disparity`` the searched range (px). ``disparity_filter`` applies OpenCV's WLS filter (contrib
    modules) and returns its map scaled to 0..255; ``depth_completion`` fills holes morphologically.
    ``baseline`` (m) and ``K`` (hybridgen's additions) default to the camera's interocular distance and
    intrinsics (``fx`` is the focal length in pixels).
    """
    if window_size % 2 == 0:
        raise ValueError(f"{_CALL}: window_size must be odd, got {window_size}")
    if not (num_disparities > 0 and num_disparities % 16 == 0):
        raise ValueError(f"{_CALL}: num_disparities must be > 0 and divisible by 16, got {num_disparities}")
    cv2 = require_cv2(_CALL, contrib=disparity_filter)
    baseline = stereo_baseline() if baseline is None else float(baseline)
    if not baseline:
        raise ValueError(f"{_CALL}: the stereo baseline is 0: set bproc.camera.set_stereo_parameters first")
    depth_max = distance_range_end() if depth_max is None else float(depth_max)
    focal_length = float(camera_K(K)[0, 0])
    options = dict(window_size=window_size, num_disparities=num_disparities, min_disparity=min_disparity,
                   disparity_filter=disparity_filter, depth_completion=depth_completion)
    depths, disparities = [], []
    for pair in color_images:
        depth, disparity = _match_pair(cv2, pair[0], pair[1], baseline, depth_max, focal_length, options)
        depths.append(depth)
        disparities.append(disparity)
    return depths, disparities
