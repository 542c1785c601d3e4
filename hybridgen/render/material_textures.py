"""Decoding of a material's data maps (roughness, metallic, alpha, normal, displacement) for both renderers.

A map is a file path or an HxW[xC] uint8 (or float 0..1) array. Data maps are linear values, never sRGB
decoded; a gray map is its first channel (an RGB image of a gray map has equal channels). A color image used as
height (:func:`color_height`) is the exception: it is read as the color Blender links to a float input.
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


REC709_LUMINANCE = np.array([0.2126, 0.7152, 0.0722], np.float32)
"""Blender 4.2's luminance weights of linear RGB (its default OpenColorIO scene-linear space, Rec.709)."""


def color_height(texture: Any, owner: str, slot: str) -> np.ndarray:
    """HxWx1 float32 height of an sRGB color image (a path or an HxWxC uint8 / float 0..1 array; alpha
    ignored): the Rec.709 luminance of its linear (sRGB-decoded) RGB. What Cycles makes of an Image Texture's
    Color linked to a float input (BlenderProc's ``set_displacement_from_principled_shader_value`` and v1's
    ``cf_color_link_to_displacement`` link Base Color's image through a Math node into the displacement):
    fitted on Cycles' bumped normals in bpy 4.2, the weights of the linear channels came out 0.2121, 0.7150,
    0.0718 (tests/render/test_bump_from_color.py checks the bump against Cycles' normals, tools/bump_vs_cycles.py).
    Cycles interpolates the 8-bit sRGB texels before decoding them; this decodes first (a bilinear height)."""
    from .tonemap import srgb_decode

    array = _decoded(texture, owner, slot)
    channels = array[..., :3] if array.shape[-1] >= 3 else np.repeat(array[..., :1], 3, axis=-1)
    if array.dtype == np.uint8:  # each of the 256 codes decoded once (the same values, a table lookup)
        linear = srgb_decode(np.arange(256, dtype=np.float32) / 255.0)[channels]
    else:
        linear = srgb_decode(channels.astype(np.float32))
    return np.ascontiguousarray((linear @ REC709_LUMINANCE)[..., None], dtype=np.float32)


def alpha_coverage(texture: Any, owner: str) -> np.ndarray:
    """HxW uint8 alpha map for the raster passes, rows bottom-up (GL's order, like UV v)."""
    values = data_image(texture, owner, "alpha_texture")[..., 0]
    return np.ascontiguousarray(np.clip(np.rint(values * 255.0), 0, 255).astype(np.uint8)[::-1])
