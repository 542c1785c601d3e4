"""Linear radiance -> display values.

``colors`` is the *standard* sRGB view of the linear HDR render: every channel is clipped to [0, 1],
encoded with the sRGB transfer function (IEC 61966-2-1: 12.92 x below 0.0031308, else
1.055 x^(1/2.4) - 0.055) and rounded to the nearest of 0..255. No exposure change, no filmic curve.
"""
from __future__ import annotations

import numpy as np


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    """sRGB transfer function of values clipped to [0, 1] (float32 in, float32 out)."""
    x = np.clip(np.nan_to_num(linear, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0).astype(np.float32)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4, dtype=np.float32) - 0.055)


def srgb_decode(values: np.ndarray) -> np.ndarray:
    """Linear values of sRGB-encoded values in 0..1 (IEC 61966-2-1; the inverse of :func:`srgb_encode`)."""
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def to_srgb8(linear: np.ndarray) -> np.ndarray:
    """uint8 sRGB image of a linear RGB image."""
    return np.rint(srgb_encode(linear) * 255.0).astype(np.uint8)


def to_srgb16(linear: np.ndarray) -> np.ndarray:
    """uint16 sRGB image of a linear RGB image (the same transfer, rounded to the nearest of 0..65535)."""
    return np.rint(srgb_encode(linear).astype(np.float64) * 65535.0).astype(np.uint16)
