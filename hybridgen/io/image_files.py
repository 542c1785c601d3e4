"""Image and array files for the dataset writers and ``hybridgen extract``: PNG (8 and 16 bit), JPEG, EXR, npy.

Every file is written under a hidden temporary name in its folder and renamed when complete, so a file
under its final name is always whole (docs/conventions.md section 4). :func:`write_file` renames at once;
:class:`StagedFiles` keeps the temporary files until :meth:`StagedFiles.commit` renames them all (or
:meth:`StagedFiles.discard` deletes them), for writers whose outputs only count once the run succeeded.
Image files are renamed without ``fsync`` (a crash of the process never leaves a partial file under the
final name; the index files that reference them are fsynced by their writers).
"""
from __future__ import annotations

import io
import json
import os
import struct
import zlib
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ..config.options import option
from ..errors import InputError, SystemSetupError
from .atomic import commit, prepare_output_dir, temporary_path
from ..input_paths import utf8_path

EXR_HINT = "EXR files are written with Mitsuba's Bitmap (the `mitsuba` package); it failed to import"
COLOR_FORMATS = ("PNG", "JPEG")


def color_format_option(doc: str) -> Any:
    """The ``color_file_format`` option of a dataset writer (PNG or JPEG)."""
    return option("PNG", "str", doc, choices=COLOR_FORMATS)


def jpg_quality_option() -> Any:
    """The ``jpg_quality`` option of a dataset writer."""
    return option(95, "int", "JPEG quality 1..100",
                  check=lambda v: None if 1 <= v <= 100 else f"must be in 1..100, got {v}")


# ----------------------------------------------------------------------------------------------- encoders
def png_bytes(image: np.ndarray, compress_level: int = 6) -> bytes:
    """PNG file bytes of a uint8 or uint16 image: (H, W) grey, (H, W, 3) RGB or (H, W, 4) RGBA.

    16-bit samples are stored big-endian, as PNG requires; values are stored exactly as given.
    """
    array = np.asarray(image)
    if array.dtype not in (np.uint8, np.uint16):
        raise InputError(f"PNG needs uint8 or uint16 values, got {array.dtype}")
    if array.ndim == 3 and array.shape[2] == 1:
        array = array[..., 0]
    if array.ndim == 2:
        color_type = 0
    elif array.ndim == 3 and array.shape[2] in (3, 4):
        color_type = 2 if array.shape[2] == 3 else 6
    else:
        raise InputError(f"PNG needs an (H, W), (H, W, 3) or (H, W, 4) image, got shape {array.shape}")
    height, width = array.shape[:2]
    if height == 0 or width == 0:
        raise InputError(f"cannot write an empty {width}x{height} image")
    depth = 8 if array.dtype == np.uint8 else 16
    samples = np.ascontiguousarray(array, dtype=">u2" if depth == 16 else np.uint8)
    raw = samples.view(np.uint8).reshape(height, -1)
    rows = np.empty((height, 1 + raw.shape[1]), dtype=np.uint8)
    rows[:, 0] = 2  # filter type "Up" for every row: each byte minus the byte above (mod 256)
    rows[0, 1:] = raw[0]
    np.subtract(raw[1:], raw[:-1], out=rows[1:, 1:])

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, depth, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(rows.tobytes(), compress_level)) + chunk(b"IEND", b""))


def jpeg_bytes(rgb: np.ndarray, quality: int = 95) -> bytes:
    """JPEG file bytes of a uint8 (H, W, 3) image (4:4:4 chroma at quality >= 90, as BOP's tools use)."""
    from PIL import Image

    array = np.asarray(rgb)
    if array.dtype != np.uint8 or array.ndim != 3 or array.shape[2] != 3:
        raise InputError(f"JPEG needs a uint8 (H, W, 3) image, got {array.dtype} {array.shape}")
    buffer = io.BytesIO()
    Image.fromarray(array).save(buffer, format="JPEG", quality=int(quality),
                                subsampling=0 if quality >= 90 else 2)
    return buffer.getvalue()


def _mitsuba() -> Any:
    try:
        import mitsuba
    except ImportError as exc:  # pragma: no cover - mitsuba is a hard dependency
        raise SystemSetupError(f"{EXR_HINT}: {exc}") from None
    return mitsuba


def write_exr_file(path: Path, image: np.ndarray, channel_names: Sequence[str] | None = None) -> None:
    """Write an OpenEXR file (float16, float32 or uint32 samples, 1..n channels) to ``path`` (not atomic).

    Channel names default to Y (1 channel), RGB (3) or RGBA (4); others need ``channel_names``.
    """
    mi = _mitsuba()
    array = np.asarray(image)
    if array.dtype not in (np.float16, np.float32, np.uint32):
        array = array.astype(np.float32)
    array = np.ascontiguousarray(array)
    if array.ndim == 2:
        array = array[..., None]
    channels = array.shape[2]
    formats = {1: mi.Bitmap.PixelFormat.Y, 3: mi.Bitmap.PixelFormat.RGB, 4: mi.Bitmap.PixelFormat.RGBA}
    if channel_names is None and channels in formats:
        bitmap = mi.Bitmap(array, formats[channels])
    else:
        names = list(channel_names or [f"C{i}" for i in range(channels)])
        if len(names) != channels:
            raise InputError(f"{channels} channels need {channels} names, got {names}")
        bitmap = mi.Bitmap(array, mi.Bitmap.PixelFormat.MultiChannel, names)
    try:
        os.fspath(path).encode("utf-8")
    except UnicodeEncodeError:  # Mitsuba takes UTF-8 names: encode in memory, write the bytes here
        stream = mi.MemoryStream()
        bitmap.write(stream, mi.Bitmap.FileFormat.OpenEXR)
        with open(path, "wb") as handle:
            handle.write(bytes(stream.raw_buffer())[:stream.size()])
        return
    bitmap.write(os.fspath(path), mi.Bitmap.FileFormat.OpenEXR)


def read_exr(path: str | Path) -> np.ndarray:
    """The samples of an OpenEXR file as an (H, W) or (H, W, C) array."""
    mi = _mitsuba()
    array = np.array(mi.Bitmap(utf8_path(path)))
    return array[..., 0] if array.ndim == 3 and array.shape[2] == 1 else array


def npy_bytes(array: np.ndarray) -> bytes:
    """``.npy`` file bytes of ``array`` (exact dtype and shape)."""
    buffer = io.BytesIO()
    np.save(buffer, np.asarray(array), allow_pickle=False)
    return buffer.getvalue()


def json_bytes(value: Any, *, indent: int | None = None) -> bytes:
    """UTF-8 JSON text of ``value``."""
    return json.dumps(value, indent=indent).encode("utf-8")


# ------------------------------------------------------------------------------------------ atomic files
def write_file(path: Path, data: bytes | Callable[[Path], None], *, durable: bool = False) -> Path:
    """Write ``data`` (bytes, or a function writing the given temporary path) to ``path`` atomically."""
    temp = temporary_path(path)
    try:
        if callable(data):
            data(temp)
        else:
            temp.write_bytes(data)
        if durable:
            commit(temp, path)
        else:
            os.replace(temp, path)
    except OSError as exc:
        temp.unlink(missing_ok=True)
        raise InputError(f"cannot write '{path}': {exc.strerror or exc}") from None
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
    return path


class StagedFiles:
    """Files written now under temporary names and renamed to their final names together at the end."""

    def __init__(self) -> None:
        self._pending: dict[Path, Path] = {}  # final -> temporary
        self._made_dirs: list[Path] = []

    def __len__(self) -> int:
        return len(self._pending)

    def __contains__(self, final: Path) -> bool:
        return final in self._pending

    def make_dir(self, directory: Path) -> Path:
        """Create ``directory`` (and parents); the ones created here are removed again by :meth:`discard`."""
        missing = []
        for folder in (directory, *directory.parents):
            if folder.exists():
                break
            missing.append(folder)
        prepare_output_dir(directory)
        self._made_dirs.extend(missing)
        return directory

    def add(self, final: Path, data: bytes | Callable[[Path], None]) -> None:
        """Write ``data`` under ``final``'s temporary name now; it gets ``final`` on :meth:`commit`."""
        temp = temporary_path(final)
        try:
            if callable(data):
                data(temp)
            else:
                temp.write_bytes(data)
        except OSError as exc:
            temp.unlink(missing_ok=True)
            raise InputError(f"cannot write '{final}': {exc.strerror or exc}") from None
        self._pending[final] = temp

    def commit(self) -> list[Path]:
        """Rename every staged file to its final name; returns the final paths."""
        done = []
        for final, temp in list(self._pending.items()):
            os.replace(temp, final)
            del self._pending[final]
            done.append(final)
        self._made_dirs.clear()
        return done

    def discard(self) -> None:
        """Delete every staged file and the (then empty) folders this object created."""
        for temp in self._pending.values():
            temp.unlink(missing_ok=True)
        self._pending.clear()
        for folder in sorted(set(self._made_dirs), key=lambda p: len(p.parts), reverse=True):
            try:
                folder.rmdir()
            except OSError:
                pass
        self._made_dirs.clear()
