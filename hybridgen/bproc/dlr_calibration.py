"""DLR-RMC camera calibration files (written by DLR CalDe / CalLab) and
``bproc.camera.set_camera_parameters_from_config_file`` (BlenderProc's LensDistortionUtility).

The format is ``key=value`` lines; ``#`` starts a comment. Keys of one camera of a rig are ``camera.<n>.<name>``;
BlenderProc reads the camera ``camera_index`` and the file-wide keys (``version``, ``origin``) and ignores other
cameras' keys and ``camera.<name>`` keys without an index (CalLab writes rig-wide values such as
``camera.rmsInt`` that way). A value is a number, a word (``origin=center``) or a MATLAB-style matrix
``[a b c; d e f; ...]`` (rows separated by ``;``; a row without ``;`` is a plain list). A later line with the same
key replaces an earlier one; lines with no ``=`` or more than one are skipped.

What BlenderProc needs from the file (and what it does with it):

* ``version=2`` and ``origin=center`` (pixel coordinates from the centre of the top-left pixel);
* ``A`` = ``[fx skew cx; 0 fy cy; 0 0 1]`` (px), ``width`` and ``height`` (px): the intrinsics
  (``set_intrinsics_from_K_matrix``);
* ``k1`` (and optionally ``k2``, ``k3``, ``p1``, ``p2``, default 0): Brown-Conrady distortion, undistorted to
  distorted, CalLab's p1/p2 order (``set_lens_distortion``: the camera is enlarged to the render the distorted
  image needs);
* with ``read_the_extrinsics``: ``R`` (3x3) and ``T`` (3, m) with ``Pw = R Pc + T`` for a point ``Pc`` in the
  camera's OpenCV axes (x right, y down, z forward): the cam2world, turned into Blender's camera axes (x right, y
  up, looking along -z) and keyed as a new camera pose (``add_camera_pose``).

Beyond BlenderProc (which feeds its rewrite of the lines to YAML): spaces around a key are ignored, numbers in
exponent form without a dot (``1e-5``) are numbers, and ``T`` may be written as a column (``[x; y; z]``); files
BlenderProc reads are read the same. Its errors are one-line :class:`~hybridgen.errors.InputError` naming the
file and key.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..logs import LOGGER

_SEPARATORS = re.compile(r"[\s,]+")


@dataclass(frozen=True)
class Malformed:
    """A value that is neither a number, a word nor a matrix of numbers (kept to name it in an error)."""

    text: str


def _scalar(text: str) -> Any:
    """An int, a float, (unquoted) a word, or None for nothing."""
    if not text:
        return None
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        return text[1:-1]
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def _matrix(text: str) -> Any:
    """``[a b; c d]`` as a list of rows, ``[a b c]`` as a flat list (numbers split by spaces or commas)."""
    inner = text[text.find("[") + 1:text.rfind("]")]
    rows = []
    for row in inner.split(";"):
        try:
            rows.append([float(token) for token in _SEPARATORS.split(row.strip()) if token])
        except ValueError:
            return Malformed(text)
    return rows if ";" in inner else rows[0]


def parse_calibration_text(text: str, camera_index: int = 0) -> dict[str, Any]:
    """The file-wide entries and those of camera ``camera_index`` (its ``camera.<n>.`` prefix removed)."""
    prefix = f"camera.{int(camera_index)}."
    entries: dict[str, Any] = {}
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if line.count("=") != 1:
            continue
        key, value = (part.strip() for part in line.split("="))
        if key.startswith("camera."):
            if not key.startswith(prefix):
                continue  # another camera's key, or a rig-wide camera.<name>
            key = key[len(prefix):]
        if not key:
            continue
        entries[key] = _matrix(value) if "[" in value and "]" in value else _scalar(value)
    return entries


def _number(entries: dict[str, Any], key: str, path: str, default: float | None = None) -> float:
    value = entries.get(key, default)
    if value is None:
        raise InputError(f"{path}: the DLR-RMC camera calibration file has no {key}")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{path}: {key} must be a number, got {getattr(value, 'text', value)!r}")
    return float(value)


def _pixels(entries: dict[str, Any], key: str, path: str) -> int:
    value = _number(entries, key, path)
    if value != int(value) or value < 1:
        raise InputError(f"{path}: {key} must be a positive whole number of pixels, got {entries[key]!r}")
    return int(value)


def _array(entries: dict[str, Any], key: str, path: str, shape: tuple[int, ...]) -> np.ndarray:
    value = entries.get(key)
    if value is None:
        raise InputError(f"{path}: the DLR-RMC camera calibration file has no {key}")
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        array = np.zeros(0)
    if array.size != int(np.prod(shape)) or (len(shape) == 2 and array.shape != shape):
        kind = "3x3 matrix" if len(shape) == 2 else f"{shape[0]}-vector"
        raise InputError(f"{path}: {key} must be a {kind} of numbers, got {getattr(value, 'text', value)!r}")
    return array.reshape(shape)


def check_version_and_origin(entries: dict[str, Any], path: str) -> None:
    """BlenderProc's requirements: ``version=2`` and ``origin=center``."""
    version = entries.get("version")
    if version is None:
        raise InputError(f"{path}: the version tag is not set in the DLR-RMC camera calibration file")
    if isinstance(version, bool) or version != 2:
        raise InputError(f"{path}: only version 2 of the DLR-RMC camera calibration file is supported, not "
                         f"{getattr(version, 'text', version)}")
    if entries.get("origin") != "center":
        raise InputError(f"{path}: the origin in the DLR-RMC camera calibration file has to be set to center "
                         f"(got {entries.get('origin')!r})")


@dataclass
class CameraCalibration:
    """What BlenderProc takes from one camera of a calibration file: the image size (px), K (px), the distortion
    coefficients (k1, k2, k3, p1, p2) and, when the extrinsics were asked for, the cam2world in Blender's camera
    axes (m; None otherwise)."""

    width: int
    height: int
    K: np.ndarray
    distortion: tuple[float, float, float, float, float]
    cam2world: np.ndarray | None


def read_camera_calibration(camera_intrinsics_file_path: str, read_the_extrinsics: bool = False,
                            camera_index: int = 0) -> CameraCalibration:
    """Camera ``camera_index`` of a DLR-RMC calibration file (module docstring), checked as BlenderProc checks it;
    ``bproc.camera.set_camera_parameters_from_config_file`` applies it."""
    from .math import change_source_coordinate_frame_of_transformation_matrix

    path = str(camera_intrinsics_file_path)
    if not os.path.exists(path):
        raise InputError(f"The camera intrinsics file does not exist: {path}")
    with open(path, encoding="utf-8") as handle:
        entries = parse_calibration_text(handle.read(), camera_index)
    LOGGER.debug("DLR-RMC camera calibration %s, camera %d: %s", path, camera_index, entries)
    check_version_and_origin(entries, path)
    width, height = _pixels(entries, "width", path), _pixels(entries, "height", path)
    K = _array(entries, "A", path, (3, 3))
    k1 = _number(entries, "k1", path)
    k2, k3, p1, p2 = (_number(entries, key, path, 0.0) for key in ("k2", "k3", "p1", "p2"))
    cam2world = None
    if read_the_extrinsics:
        opencv = np.eye(4)
        opencv[:3, :3] = _array(entries, "R", path, (3, 3))
        opencv[:3, 3] = _array(entries, "T", path, (3,))
        cam2world = change_source_coordinate_frame_of_transformation_matrix(opencv, ["X", "-Y", "-Z"])
    return CameraCalibration(width, height, K, (k1, k2, k3, p1, p2), cam2world)
