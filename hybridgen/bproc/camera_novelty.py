"""``bproc.camera.check_novel_pose`` (BlenderProc's CameraValidation): is a sampled camera pose new enough,
judged by how much it raises the variance of the poses accepted so far.

BlenderProc's test, as it behaves: with no existing pose every pose is novel. Otherwise, for the rotation (when
``check_pose_novelty_rot``) and then the translation (``check_pose_novelty_translation``):

* the values are Blender ``XYZ`` Euler angles (rad, as ``mathutils.Matrix.to_euler()`` chooses them) or
  translations (m) of the existing cam2world matrices;
* the old variance is ``np.var`` over *all* their components together (3 N numbers, not one variance per
  axis); the new variance is the same over those values plus the candidate's three (appended to a scratch list:
  ``existing_poses`` is never changed);
* the pose fails if the new variance is smaller than the old one, or if the increase
  ``(new - old) / old * 100`` (percent) is below the threshold (``min_var_diff_rot`` /
  ``min_var_diff_translation``; the default -1 only asks that the variance does not drop, and an equal variance
  passes);
* an old variance of exactly 0 (one existing pose whose three values are equal, e.g. the identity rotation or a
  camera at the origin) makes the increase infinite (or NaN for 0 / 0), which no threshold rejects: the
  candidate passes that test.

Blender's ``mathutils`` holds matrices and angles in single precision; the poses and the Euler angles and
translations are rounded to float32 here too, so that two poses whose values Blender stores equally give the same
variances (a repeated pose then keeps the variance exactly where Blender keeps it).
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..logs import LOGGER
from .math import blender_euler_from_matrix


def _single(matrix: Any, what: str) -> np.ndarray:
    """A 4x4 (or, for rotations only, 3x3) matrix as Blender stores it: float32 values, returned as float64."""
    array = np.asarray(matrix, dtype=np.float64)
    if array.shape not in ((4, 4), (3, 3)) or not np.all(np.isfinite(array)):
        raise InputError(f"{what} must be a finite 4x4 matrix, got shape {array.shape}")
    return array.astype(np.float32).astype(np.float64)


def _euler(matrix: np.ndarray) -> np.ndarray:
    """Blender's ``to_euler()`` (XYZ, rad) of a stored matrix, rounded to float32 as Blender returns it."""
    return blender_euler_from_matrix(matrix[:3, :3]).astype(np.float32).astype(np.float64)


def _translation(matrix: np.ndarray, what: str) -> np.ndarray:
    if matrix.shape != (4, 4):
        raise InputError(f"{what} must be a 4x4 matrix to check its translation, got shape {matrix.shape}")
    return matrix[:3, 3]


def _raises_variance(values: list[np.ndarray], candidate: np.ndarray, min_increase_percent: float,
                     what: str) -> bool:
    """Whether appending ``candidate`` to ``values`` raises ``np.var`` over all components by at least
    ``min_increase_percent`` percent of the old variance (an old variance of 0 always passes)."""
    old = float(np.var(values))
    new = float(np.var([*values, candidate]))
    if new < old:
        return False
    if old == 0.0:
        LOGGER.debug("check_novel_pose: the %s variance was 0: novel", what)
        return True
    increase = (new - old) / old * 100.0
    LOGGER.debug("check_novel_pose: %s variance up %.6g %%", what, increase)
    return not increase < float(min_increase_percent)


def check_novel_pose(cam2world_matrix: Any, existing_poses: Sequence[Any], check_pose_novelty_rot: bool,
                     check_pose_novelty_translation: bool, min_var_diff_rot: float = -1,
                     min_var_diff_translation: float = -1) -> bool:
    """Whether the Blender-axes ``cam2world_matrix`` (4x4, m) is novel against ``existing_poses`` (the accepted
    cam2world matrices) by BlenderProc's variance test (module docstring): the rotation test first, then the
    translation test; thresholds in percent of the old variance."""
    if len(existing_poses) == 0:
        return True
    candidate = _single(cam2world_matrix, "cam2world_matrix")
    poses = [_single(pose, "existing_poses[i]") for pose in existing_poses]
    if check_pose_novelty_rot and not _raises_variance([_euler(p) for p in poses], _euler(candidate),
                                                       min_var_diff_rot, "rotation"):
        return False
    if check_pose_novelty_translation and not _raises_variance(
            [_translation(p, "existing_poses[i]") for p in poses], _translation(candidate, "cam2world_matrix"),
            min_var_diff_translation, "translation"):
        return False
    return True
