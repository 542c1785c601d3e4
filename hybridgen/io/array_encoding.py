"""The per-array encodings of compact label storage, without the file layer (no render or HDF5 imports, so
that the raster passes can hand over arrays already encoded): encoding names, the octahedral normal codes,
integer narrowing and :class:`EncodedArray`. What each encoding means and how files carry it:
:mod:`hybridgen.io.label_encoding`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NARROWED = "narrowed_integer"
OCTAHEDRAL = "octahedral_uint16"
DERIVED_DISTANCE = "derived_from_depth"

OCTAHEDRAL_MAX_ERROR_RAD = 1e-4
"""Stated bound on the angle between a normal and its decoded octahedral code (see the module doc)."""

_OCT_SCALE = 32767.0  # q in [-1, 1] -> (q + 1) * 32767 in [0, 65534], + 1: codes 1..65535, 0 = background


@dataclass(frozen=True)
class EncodedArray:
    """A pass value already in its stored form (made by the raster pass itself, render/raster/label_targets.py):
    ``stored`` is what a writer stores under ``tag`` (:func:`storage_tag`); renderers hand such values only to
    sinks that said they store that tag (``accepted_encodings()``). :meth:`decode` gives the documented values."""

    stored: np.ndarray
    tag: str

    def decode(self) -> np.ndarray:
        encoding, *dtypes = self.tag.split(":")
        if encoding == OCTAHEDRAL:
            return decode_octahedral(self.stored)
        if encoding == NARROWED:
            return self.stored.astype(dtypes[0])
        raise ValueError(f"unknown encoding tag {self.tag!r}")


def storage_tag(encoding: str, stored: np.dtype, decoded: np.dtype) -> str:
    """The tag naming one stored form: ``octahedral_uint16``, or ``narrowed_integer:<stored>:<decoded>``."""
    if encoding == OCTAHEDRAL:
        return OCTAHEDRAL
    return f"{encoding}:{np.dtype(decoded).name}:{np.dtype(stored).name}"


def narrowest_integer_dtype(low: int, high: int) -> np.dtype:
    """The smallest integer dtype holding every value in [low, high] (unsigned when low >= 0)."""
    for name in (("uint8", "uint16", "uint32") if low >= 0 else ("int8", "int16", "int32")):
        info = np.iinfo(name)
        if info.min <= low and high <= info.max:
            return np.dtype(name)
    return np.dtype("int64")


def encode_octahedral(normals: np.ndarray) -> np.ndarray:
    """(…, 3) unit normals (float32, any strides) -> (…, 2) uint16 octahedral codes; (0, 0, 0) -> (0, 0)."""
    x, y, z = normals[..., 0], normals[..., 1], normals[..., 2]
    l1 = np.abs(x, dtype=np.float32)
    l1 += np.abs(y)
    l1 += np.abs(z)
    background = l1 == 0
    inverse = np.divide(np.float32(1), l1, out=np.zeros_like(l1), where=~background)
    px, py = x * inverse, y * inverse
    lower = z < 0  # fold the lower hemisphere over the diagonals
    fold_x = np.copysign(1 - np.abs(py), px)
    fold_y = np.copysign(1 - np.abs(px), py)
    codes = np.empty((*l1.shape, 2), dtype=np.uint16)
    for channel, p, fold in ((0, px, fold_x), (1, py, fold_y)):
        np.copyto(p, fold, where=lower)
        p += 1
        p *= np.float32(_OCT_SCALE)
        np.rint(p, out=p)
        p += 1
        p[background] = 0
        codes[..., channel] = p
    return codes


def decode_octahedral(codes: np.ndarray) -> np.ndarray:
    """(…, 2) uint16 octahedral codes -> (…, 3) float32 unit normals; code (0, 0) -> (0, 0, 0)."""
    q = (np.asarray(codes, dtype=np.float64) - 1.0) / _OCT_SCALE - 1.0
    px, py = q[..., 0], q[..., 1]
    z = 1.0 - np.abs(px) - np.abs(py)
    lower = z < 0
    x = np.where(lower, np.copysign(1.0 - np.abs(py), px), px)
    y = np.where(lower, np.copysign(1.0 - np.abs(px), py), py)
    out = np.stack([x, y, z], axis=-1)
    out /= np.linalg.norm(out, axis=-1, keepdims=True)
    out[(codes[..., 0] == 0) & (codes[..., 1] == 0)] = 0.0
    return out.astype(np.float32)
