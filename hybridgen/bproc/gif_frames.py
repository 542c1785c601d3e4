"""The frames of BlenderProc's GIF animations: the RGBA image BlenderProc's ``vis_data`` (its hdf5 viewer) saves
for one key's value with matplotlib's ``imsave``, computed with NumPy alone (no matplotlib needed).

By key (regular expressions matched against the whole key, as BlenderProc matches them):

- ``colors``, ``normals``, ``diffuse``, ``nocs`` and any other (H, W, 3|4) value: the image itself, uint8 as
  given, floats in [0, 1] times 255 truncated; alpha 255 when there is none.
- ``segmap`` and ``.*_segmaps``: matplotlib's ``jet`` from the frame's smallest to its largest value.
- ``depth``, ``distance``, ``stereo-depth`` (m): ``summer`` from the frame's smallest value to 20 m (farther
  pixels, the background among them, take the top color); of a multi-channel value the first channel.
- any other (H, W) value: ``viridis`` from its smallest to its largest value.

Colormaps are matplotlib's 256-entry tables as bytes (entries * 255, truncated); a value ``v`` normalized to
``t = (v - low) / (high - low)`` in the value's float precision (float32 stays float32, integers become float64)
takes entry ``floor(t * 256)`` clipped to 0..255 (t = 1: the last); NaN is transparent black.
"""
from __future__ import annotations

import re
from typing import Sequence

import numpy as np

from ..errors import InputError
from ..io.colormaps import VIRIDIS_BYTES
from .types.unsupported import fail

RGB_KEYS = ("colors", "normals", "diffuse", "nocs")
FLOW_KEYS = ("forward_flow", "backward_flow")
SEGMAP_KEYS = ("segmap", ".*_segmaps")
DEPTH_KEYS = ("distance", "depth", "stereo-depth")
DEPTH_MAX = 20.0
"""The top of the depth color scale (m), BlenderProc's viewer default."""
LUT_SIZE = 256

# matplotlib's linear segments per channel: (x, value) pairs, linear in between
_JET = {"red": ((0.0, 0.0), (0.35, 0.0), (0.66, 1.0), (0.89, 1.0), (1.0, 0.5)),
        "green": ((0.0, 0.0), (0.125, 0.0), (0.375, 1.0), (0.64, 1.0), (0.91, 0.0), (1.0, 0.0)),
        "blue": ((0.0, 0.5), (0.11, 1.0), (0.34, 1.0), (0.65, 0.0), (1.0, 0.0))}
_SUMMER = {"red": ((0.0, 0.0), (1.0, 1.0)), "green": ((0.0, 0.5), (1.0, 1.0)), "blue": ((0.0, 0.4), (1.0, 0.4))}


def _segment_channel(points: Sequence[tuple[float, float]]) -> np.ndarray:
    """One channel's 256 entries in [0, 1], evaluated as matplotlib evaluates linear segments (at i / 255)."""
    x = np.array([p[0] for p in points]) * (LUT_SIZE - 1)
    y = np.array([p[1] for p in points])
    samples = (LUT_SIZE - 1) * np.linspace(0, 1, LUT_SIZE)
    index = np.searchsorted(x, samples)[1:-1]
    distance = (samples[1:-1] - x[index - 1]) / (x[index] - x[index - 1])
    inner = distance * (y[index] - y[index - 1]) + y[index - 1]
    return np.clip(np.concatenate([[y[0]], inner, [y[-1]]]), 0.0, 1.0)


def segment_lut(segments: dict[str, Sequence[tuple[float, float]]]) -> np.ndarray:
    """(256, 4) uint8 RGBA table of a linear-segmented colormap."""
    channels = [_segment_channel(segments[name]) for name in ("red", "green", "blue")]
    return (np.stack([*channels, np.ones(LUT_SIZE)], axis=-1) * 255).astype(np.uint8)


JET, SUMMER = segment_lut(_JET), segment_lut(_SUMMER)
VIRIDIS = np.concatenate([VIRIDIS_BYTES, np.full((LUT_SIZE, 1), 255, np.uint8)], axis=1)


def matches(key: str, patterns: Sequence[str]) -> bool:
    return any(re.fullmatch(pattern, key) for pattern in patterns)


def scalar_image(values: np.ndarray, lut: np.ndarray, vmax: float | None = None) -> np.ndarray:
    """(H, W, 4) uint8 of an (H, W) image through ``lut``, normalized from its minimum to ``vmax`` (default: its
    maximum)."""
    data = np.asarray(values)
    if data.dtype.kind in "biu":
        data = data.astype(np.promote_types(data.dtype, np.float32))
    else:
        data = data.astype(data.dtype if data.dtype.kind == "f" else np.float64, copy=True)
    low = data.min()
    high = data.dtype.type(vmax) if vmax is not None else data.max()
    if low == high:
        data.fill(0)
    else:
        data -= low
        data /= high - low
    scaled = data * data.dtype.type(LUT_SIZE)
    scaled[scaled == LUT_SIZE] = LUT_SIZE - 1
    bad = np.isnan(scaled)
    with np.errstate(invalid="ignore"):
        index = np.clip(np.where(bad, 0, scaled), -1, LUT_SIZE).astype(np.int64)
    image = lut[np.clip(index, 0, LUT_SIZE - 1)]
    image[bad] = 0
    return image


def color_image(values: np.ndarray) -> np.ndarray:
    """(H, W, 4) uint8 of an (H, W, 3|4) image: uint8 as given, floats in [0, 1] times 255 (truncated)."""
    data = np.asarray(values)
    if data.dtype.kind == "f":
        if data.min() < 0 or data.max() > 1:
            raise InputError("GIF frames of float RGB images need values in 0..1 (as matplotlib's imsave)")
        data = (data * 255).astype(np.uint8)
    elif data.dtype != np.uint8:
        raise InputError(f"GIF frames of RGB images need uint8 or float values, got {data.dtype}")
    if data.shape[2] == 3:
        data = np.concatenate([data, np.full(data.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return data


def frame_image(key: str, value: np.ndarray) -> np.ndarray:
    """The (H, W, 4) uint8 frame BlenderProc's viewer makes of ``key``'s ``value`` (see the module doc)."""
    data = np.asarray(value)
    if matches(key, FLOW_KEYS):
        fail(f"bproc.writer.write_gif_animation of '{key}'", "optical flow frames need OpenCV's HSV colors")
    if matches(key, SEGMAP_KEYS):
        if data.ndim == 3 and data.shape[2] != 1:
            fail(f"bproc.writer.write_gif_animation of the {data.shape[2]}-channel '{key}'",
                 "BlenderProc 2.8 fails there too")
        return scalar_image(data.reshape(data.shape[:2]), JET)
    if matches(key, DEPTH_KEYS):
        return scalar_image(data[:, :, 0] if data.ndim == 3 else data, SUMMER, DEPTH_MAX)
    if data.ndim == 2:
        return scalar_image(data, VIRIDIS)
    if data.ndim == 3 and data.shape[2] in (3, 4):
        return color_image(data)
    raise InputError(f"bproc.writer.write_gif_animation: '{key}' of shape {data.shape} is not an image")
