"""Decoding of a material's data maps (roughness, metallic, alpha, normal, displacement) for both renderers.

A map is a file path or an HxW[xC] uint8 (or float 0..1) array. Data maps are linear values, never sRGB
decoded; a gray map is its first channel (an RGB image of a gray map has equal channels).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError


def _decoded(texture: Any, owner: str, slot: str) -> np.ndarray:
    if isinstance(texture, (str, Path)):
        from PIL import Image

        from ..io.image_check import check_image_file

        check_image_file(texture, f"object '{owner}': {slot} file")
        with Image.open(texture) as image:
            if image.mode in ("I;16", "I;16B", "I;16L", "I", "F"):
                array = np.asarray(image, dtype=np.float64)
                return (array / (65535.0 if image.mode.startswith("I") else 1.0))[..., None]
            return np.asarray(image.convert("RGBA" if image.mode in ("RGBA", "LA", "P") else "RGB"))
    array = np.asarray(texture)
    if array.ndim == 2:
        array = array[..., None]
    if array.ndim != 3 or array.shape[-1] not in (1, 2, 3, 4) or array.size == 0:
        raise InputError(f"object '{owner}': {slot} must be an HxW or HxWxC image, got shape {array.shape}")
    return array


def data_image(texture: Any, owner: str, slot: str, channels: int = 1) -> np.ndarray:
    """HxWx``channels`` float32 values in 0..1, rows top-down as stored in the file."""
    array = _decoded(texture, owner, slot)
    values = array.astype(np.float32) / 255.0 if array.dtype == np.uint8 else array.astype(np.float32)
    if channels == 1:
        return np.ascontiguousarray(values[..., :1])
    if values.shape[-1] < channels:
        raise InputError(f"object '{owner}': {slot} needs {channels} channels (a tangent-space normal map is RGB), "
                         f"got {values.shape[-1]}")
    return np.ascontiguousarray(values[..., :channels])


def alpha_coverage(texture: Any, owner: str) -> np.ndarray:
    """HxW uint8 alpha map for the raster passes, rows bottom-up (GL's order, like UV v)."""
    values = data_image(texture, owner, "alpha_texture")[..., 0]
    return np.ascontiguousarray(np.clip(np.rint(values * 255.0), 0, 255).astype(np.uint8)[::-1])
