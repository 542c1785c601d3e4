"""The textures a Displace modifier reads, as callables from texture-space points (N, 3) to values (N,) - what
:func:`hybridgen.scene.displace_modifier.displace` takes, from v1 configs and bproc scripts alike.

- :class:`ImageHeight`: an image texture (file path or HxW[xC] array), read as Blender 4.2's Displace modifier
  reads an IMAGE texture (measured with bpy 4.2, ``tools/blender_displace_image.py``, stored in
  tests/scene/data/blender_displace_image.json): a texture point (x, y, z) - for the default LOCAL coordinates the
  vertex in the object's mesh frame, metres - is the image point u = (x + 1) / 2, v = (y + 1) / 2 (z unused: the
  square x, y in [-1, 1] spans the image once, row 0 of the file at v = 1); the value is bilinear between texel
  centres and repeats past the image's edges; a color image gives the mean of R, G and B (alpha unused). An
  8-bit image is read as stored (/ 255) whatever its colorspace (an sRGB and a Non-Color image give the same
  displacement); a 16-bit one (/ 65535) tagged sRGB - Blender's tag of a loaded PNG or TIFF - is decoded with the
  sRGB curve first (Blender holds it as linear floats), tagged Non-Color it is read as stored. A 16-bit RGB file
  is read at 8 bits (PIL's decoding), where Blender keeps 16.
- :class:`ProceduralHeight`: one of Blender's procedural textures (:mod:`hybridgen.scene.procedural_texture`:
  CLOUDS, VORONOI, ...) with its settings, as BlenderProc 1.x's ``sampler.Texture`` creates them.

:func:`texture_key` gives the identity under which objects that share a mesh may share the displaced result.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from .procedural_texture import TYPES, displacement_value, settings_of

DATA_COLORSPACES = ("Non-Color", "Raw", "Linear")
"""Colorspaces whose values a displacement image is read as stored."""
Texture = Callable[[np.ndarray], np.ndarray]
"""A displacement texture: (N, 3) texture-space points -> (N,) values (a vertex moves by strength x (value -
mid_level))."""


def height_image(texture: Any, owner: str, colorspace: str | None = "Non-Color") -> np.ndarray:
    """HxW float64 values of an image (path or HxW[xC] array) as the Displace modifier reads them: the mean of
    R, G, B (a grey image: its one channel), 8-bit / 255, 16-bit / 65535, float as is; rows top-down as stored.
    ``colorspace`` sRGB (Blender's tag of a loaded PNG or TIFF) decodes a 16-bit or float image with the sRGB
    curve first, as Blender converts such images to linear on loading; 8-bit images are read as stored in any
    colorspace (measured, module doc). Other colorspaces than sRGB and data ones raise one line."""
    from ..render.material_textures import data_image

    if colorspace not in DATA_COLORSPACES + ("sRGB", None):
        raise InputError(f"object '{owner}': a displacement image in colorspace {colorspace!r} is not supported "
                         f"by hybridgen yet (sRGB, {', '.join(DATA_COLORSPACES)} are)")
    slot = "displacement texture"
    precise = _float_buffer(texture)
    if isinstance(texture, np.ndarray) and texture.dtype == np.uint16:
        texture = texture.astype(np.float64) / 65535.0
    try:
        values = data_image(texture, owner, slot, channels=3).astype(np.float64)
    except InputError:  # fewer than three channels: a grey image (any other problem is raised again below)
        values = data_image(texture, owner, slot).astype(np.float64)
    if precise and colorspace == "sRGB":
        from ..render.tonemap import srgb_decode

        values = srgb_decode(values)
    return values.mean(axis=-1)


def _float_buffer(texture: Any) -> bool:
    """Whether Blender holds the image as floats (16-bit or float files and arrays), not as bytes."""
    if isinstance(texture, np.ndarray):
        return texture.dtype != np.uint8
    try:
        from PIL import Image

        with Image.open(texture) as image:
            return image.mode in ("I;16", "I;16B", "I;16L", "I", "F")
    except (OSError, ValueError):
        return False  # unreadable: data_image says why


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Values of ``image`` (HxW, row 0 = top = v 1) at ``uv`` (N x 2), bilinear between texel centres,
    repeating (as Blender's and Mitsuba's image textures)."""
    height, width = image.shape
    x = uv[:, 0] * width - 0.5
    y = (1.0 - uv[:, 1]) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    x0i, y0i = x0.astype(np.int64) % width, y0.astype(np.int64) % height
    x1i, y1i = (x0i + 1) % width, (y0i + 1) % height
    top = image[y0i, x0i] * (1 - fx) + image[y0i, x1i] * fx
    bottom = image[y1i, x0i] * (1 - fx) + image[y1i, x1i] * fx
    return top * (1 - fy) + bottom * fy


@dataclass(frozen=True, eq=False)
class ImageHeight:
    """An image texture (module doc): ``image`` a file path or an HxW[xC] array; ``colorspace`` its tag (None:
    sRGB for a file, as Blender tags a loaded PNG or TIFF, Non-Color for an array); ``owner`` names it in
    errors."""

    image: Any
    colorspace: str | None = None
    owner: str = "displacement"

    @cached_property
    def values(self) -> np.ndarray:
        """HxW values (:func:`height_image`), decoded once."""
        colorspace = self.colorspace or ("Non-Color" if isinstance(self.image, np.ndarray) else "sRGB")
        return height_image(self.image, self.owner, colorspace)

    def __call__(self, points: np.ndarray) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return sample_bilinear(self.values, (p[:, :2] + 1.0) / 2.0)

    def key(self) -> tuple[str, Any, str | None]:
        """The image's identity: its path, or the array object, and the colorspace."""
        if isinstance(self.image, np.ndarray):
            return ("array", id(self.image), self.colorspace)
        return ("path", str(self.image), self.colorspace)


@dataclass(frozen=True)
class ProceduralHeight:
    """A Blender procedural texture of type ``kind`` with ``changes`` to its defaults (sorted (name, value)
    pairs); evaluated by :func:`hybridgen.scene.procedural_texture.displacement_value`."""

    kind: str
    changes: tuple[tuple[str, Any], ...] = field(default=())

    @classmethod
    def of(cls, kind: str, **changes: Any) -> "ProceduralHeight":
        """The texture ``kind`` (one of :data:`~hybridgen.scene.procedural_texture.TYPES`, any case) with
        ``changes``; one line naming an unknown type or setting."""
        kind = str(kind).upper()
        if kind not in TYPES:
            raise InputError(f"there is no procedural texture {kind!r} (Blender's: {', '.join(TYPES)})")
        unknown = sorted(set(changes) - set(settings_of(kind)))
        if unknown:
            raise InputError(f"a {kind} texture has no setting {unknown[0]!r} (Blender's: "
                             f"{', '.join(sorted(settings_of(kind)))})")
        return cls(kind, tuple(sorted(changes.items())))

    @property
    def settings(self) -> dict[str, Any]:
        """The full settings: Blender's defaults with the changes."""
        return {**settings_of(self.kind), **dict(self.changes)}

    def __call__(self, points: np.ndarray) -> np.ndarray:
        return displacement_value(self.kind, self.settings, np.asarray(points, dtype=np.float64).reshape(-1, 3))


def texture_key(texture: Texture | None) -> Any:
    """A hashable identity of ``texture`` under which two evaluations give the same values, or a fresh object
    (never equal) where they may not: white NOISE is new at every evaluation, and an unknown callable is taken
    by identity."""
    if texture is None:
        return ("none",)
    if isinstance(texture, ImageHeight):
        return texture.key()
    if isinstance(texture, ProceduralHeight):
        return object() if texture.kind == "NOISE" else texture
    return ("callable", id(texture))
