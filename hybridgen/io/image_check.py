"""Image inputs (textures, HDRIs) checked from their headers before anything decodes them.

A 109 KB PNG may declare 30000 x 30000 pixels: decoding it takes gigabytes, and Mitsuba's loader crashed the
process on it. :func:`check_image_file` reads only the header (PIL for PNG/JPEG/TGA/BMP/..., the
resolution line of Radiance ``.hdr`` files, the ``dataWindow`` attribute of OpenEXR files), refuses more
than :data:`MAX_IMAGE_PIXELS` pixels, and decodes PIL formats once to catch truncated files, so a bad
texture is one line naming the file instead of a crash in a renderer.
"""
from __future__ import annotations

import re
import struct
from pathlib import Path

from ..errors import InputError

MAX_IMAGE_PIXELS = 2**28  # 16384 x 16384
_HEADER_BYTES = 64 * 1024
_CHECKED: dict[tuple[str, int, int], tuple[int, int]] = {}  # (path, size, mtime_ns) -> (width, height)


def _hdr_size(head: bytes) -> tuple[int, int] | None:
    match = re.search(rb"\n\n([-+])Y (\d+) ([-+])X (\d+)\n", head)
    if match is None:
        match = re.search(rb"\n([-+])Y (\d+) ([-+])X (\d+)\n", head)
    return (int(match.group(4)), int(match.group(2))) if match else None


def _exr_size(head: bytes) -> tuple[int, int] | None:
    if head[:4] != b"\x76\x2f\x31\x01":
        return None
    at = head.find(b"dataWindow\0box2i\0")
    if at < 0:
        return None
    start = at + len(b"dataWindow\0box2i\0") + 4  # attribute size (16)
    x0, y0, x1, y1 = struct.unpack("<4i", head[start:start + 16])
    return x1 - x0 + 1, y1 - y0 + 1


def _pil_size(path: Path, what: str) -> tuple[int, int]:
    import warnings

    from PIL import Image

    limit = Image.MAX_IMAGE_PIXELS
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)
        Image.MAX_IMAGE_PIXELS = None  # only the header is read before our own budget is applied
        try:
            image = Image.open(path)
        finally:
            Image.MAX_IMAGE_PIXELS = limit
        with image:
            size = image.size
            if size[0] * size[1] <= MAX_IMAGE_PIXELS:
                image.load()  # a truncated or corrupt file fails here, not inside a renderer
    return size


def check_image_file(path: str | Path, what: str = "image") -> tuple[int, int]:
    """``(width, height)`` of the image at ``path``; one-line InputError when it cannot be read, is
    damaged, or has more than :data:`MAX_IMAGE_PIXELS` pixels. Results are cached per file version."""
    path = Path(path)
    try:
        stat = path.stat()
    except OSError as exc:
        raise InputError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    key = (str(path), stat.st_size, stat.st_mtime_ns)
    if key in _CHECKED:
        return _CHECKED[key]
    try:
        with open(path, "rb") as handle:
            head = handle.read(_HEADER_BYTES)
        suffix = path.suffix.lower()
        size = _hdr_size(head) if suffix == ".hdr" else _exr_size(head) if suffix == ".exr" else _pil_size(path, what)
    except InputError:
        raise
    except Exception as exc:  # PIL raises OSError, SyntaxError, ValueError ... for damaged files
        raise InputError(f"{what} '{path}' is damaged or not an image ({str(exc).splitlines()[0][:120]})") from None
    if size is None:
        raise InputError(f"{what} '{path}' has no readable {path.suffix} header")
    width, height = size
    if width <= 0 or height <= 0 or width * height > MAX_IMAGE_PIXELS:
        raise InputError(f"{what} '{path}' declares {width} x {height} pixels; the limit is {MAX_IMAGE_PIXELS} "
                         "(2**28) pixels")
    _CHECKED[key] = size
    return size
