"""Compact storage of label passes in HDF5, and the one function that reads them back (docs/conventions.md
section 3: readers get the documented dtypes, ids and depth exactly).

A dataset's attributes say how it is stored; a dataset without an ``encoding`` attribute holds its values
as they are. Encodings:

``encoding = "narrowed_integer"``
    ids stored in the smallest integer type holding the scene's values (uint8 for up to 255 objects);
    ``decoded_dtype`` names the dtype to cast back to (int32). Exact.
``encoding = "octahedral_uint16"``
    unit normals (…, 3) stored as (…, 2) uint16 codes of the octahedral map: ``q = (code - 1) / 32767 - 1``
    in [-1, 1]^2, code (0, 0) is the background normal (0, 0, 0). ``max_error_rad`` states the bound on
    the angle between a stored and a decoded normal: rounding moves the octahedral point by at most
    sqrt(2)/65534; lifting it to (px, py, 1 - |px| - |py|) stretches by at most sqrt(3) and normalizing a
    vector at least 1/sqrt(3) long by at most sqrt(3) more, so the error is below 3 sqrt(2)/65534 = 6.5e-5
    rad (plus float32 rounding); the bound stated is 1e-4 rad.
``encoding = "derived_from_depth"``
    ``distance`` is not stored (no chunk is written; a plain read gives the NaN fill value): it is
    ``depth * |((u - cx) / fx, (v - cy) / fy, 1)|`` per pixel centre, the ray length rounded to float32
    first, with ``cam_K`` of the keypoint - bit-identical to what the renderer computes. Background pixels
    (depth = ``depth_background``, which is inf or 0 for this encoding) keep that value.

:func:`decode_dataset` is what ``hybridgen.data``, ``hybridgen extract`` and ``hybridgen vis`` call.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .frame_sink import PassLayout

NARROWED = "narrowed_integer"
OCTAHEDRAL = "octahedral_uint16"
DERIVED_DISTANCE = "derived_from_depth"

OCTAHEDRAL_MAX_ERROR_RAD = 1e-4
"""Stated bound on the angle between a normal and its decoded octahedral code (see the module doc)."""

_OCT_SCALE = 32767.0  # q in [-1, 1] -> (q + 1) * 32767 in [0, 65534], + 1: codes 1..65535, 0 = background


@dataclass(frozen=True)
class EncodedArray:
    """A pass value already in its stored form (made by the raster pass itself, render/label_targets.py):
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


def ray_lengths(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W) float32 |((u - cx) / fx, (v - cy) / fy, 1)| per pixel centre (the renderer's own arithmetic)."""
    from ..scene.camera import Intrinsics

    rays = Intrinsics(np.asarray(K, dtype=np.float64), width, height).pixel_rays()
    return np.linalg.norm(rays, axis=-1).astype(np.float32)


def distance_from_depth(depth: np.ndarray, K: np.ndarray, background: float) -> np.ndarray:
    """Euclidean distance (…, H, W) float32 from camera-z ``depth`` (…, H, W) float32 sharing one 3x3 ``K``."""
    height, width = depth.shape[-2:]
    distance = np.asarray(depth, dtype=np.float32) * ray_lengths(K, width, height)
    distance[depth == background] = background
    return distance


def can_derive_distance(depth_background: float) -> bool:
    """Distance is derived exactly from depth when the background survives the product (inf or 0)."""
    return bool(np.isinf(depth_background) or depth_background == 0)


def decode_dataset(dset: Any, index: Any = ()) -> np.ndarray:
    """``dset[index]`` (an ``h5py.Dataset``) with the documented dtype and shape, whatever its storage.

    ``index`` selects along the leading (keypoint, stereo-eye) axes only; image axes are always whole for
    encoded passes.
    """
    encoding = dset.attrs.get("encoding")
    if isinstance(encoding, bytes):
        encoding = encoding.decode()
    if encoding is None:
        return dset[index]
    if encoding == NARROWED:
        return np.asarray(dset[index]).astype(str(_text(dset.attrs["decoded_dtype"])))
    if encoding == OCTAHEDRAL:
        return decode_octahedral(dset[index])
    if encoding == DERIVED_DISTANCE:
        return _derived_distance(dset, index)
    raise ValueError(f"dataset '{dset.name}' has an unknown encoding {encoding!r}; a newer hybridgen wrote it")


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _derived_distance(dset: Any, index: Any) -> np.ndarray:
    h5 = dset.file
    depth_key = _text(dset.attrs["derived_from"])
    background = float(dset.attrs["depth_background"])
    depth = np.asarray(decode_dataset(h5[depth_key], index), dtype=np.float32)
    keypoint = (index[0] if index else slice(None)) if isinstance(index, tuple) else index
    K = np.asarray(h5["cam_K"][keypoint], dtype=np.float64)
    if K.ndim == 2:
        return distance_from_depth(depth, K, background)
    out = np.empty_like(depth)
    for i in range(K.shape[0]):
        out[i] = distance_from_depth(depth[i], K[i], background)
    return out


@dataclass(frozen=True)
class StoredPass:
    """How one output key is stored: dtype and per-keypoint shape on disk, whether HDF5's shuffle filter
    runs before compression, the dataset attributes that describe the encoding, and the encoder (values
    in the documented dtype -> stored array; None: nothing is stored, the pass is derived on read)."""

    key: str
    dtype: np.dtype
    shape: tuple[int, ...]
    shuffle: bool
    attrs: dict[str, Any]
    encode: Callable[[np.ndarray], np.ndarray] | None


def _as_stored(dtype: np.dtype) -> Callable[[np.ndarray], np.ndarray]:
    return lambda value: np.ascontiguousarray(value, dtype=dtype)


def _narrowed(layout: PassLayout, dtype: np.dtype) -> Callable[[np.ndarray], np.ndarray]:
    info = np.iinfo(dtype)

    def encode(value: np.ndarray) -> np.ndarray:
        if value.size and (value.min() < info.min or value.max() > info.max):  # never wrap silently
            raise ValueError(f"'{layout.key}' holds values outside its declared range {layout.value_range}")
        return np.ascontiguousarray(value, dtype=dtype)
    return encode


def plan_storage(layout: PassLayout, *, compact: bool, keys: set[str], depth_background: float) -> StoredPass:
    """The storage of ``layout`` (a non-JSON pass). ``compact`` turns the encodings of the module doc on
    where they apply; ``keys`` are all keys of the file (distance is derived only when depth is stored)."""
    dtype = np.dtype(layout.dtype)
    plain = StoredPass(layout.key, dtype, layout.shape, dtype.kind == "f" and dtype.itemsize > 1, {},
                       _as_stored(dtype))
    if not compact:
        return plain
    from ..render.passes import exact  # here: the catalogue's raster passes import this module

    entry = exact(layout.key)  # the pass catalogue names each pass's compact encoding
    encoding = entry.hdf5 if entry is not None else ""
    if encoding == "octahedral" and dtype == np.float32 and layout.shape[-1] == 3:
        return StoredPass(layout.key, np.dtype(np.uint16), (*layout.shape[:-1], 2), False,
                          {"encoding": OCTAHEDRAL, "decoded_dtype": "float32",
                           "max_error_rad": OCTAHEDRAL_MAX_ERROR_RAD}, encode_octahedral)
    if encoding == "derived_from_depth" and "depth" in keys and can_derive_distance(depth_background):
        return StoredPass(layout.key, dtype, layout.shape, False,
                          {"encoding": DERIVED_DISTANCE, "derived_from": "depth",
                           "depth_background": float(depth_background), "decoded_dtype": "float32"}, None)
    if dtype.kind in "iu" and layout.value_range is not None:
        narrow = narrowest_integer_dtype(*layout.value_range)
        if narrow.itemsize < dtype.itemsize:
            return StoredPass(layout.key, narrow, layout.shape, False,
                              {"encoding": NARROWED, "decoded_dtype": dtype.name}, _narrowed(layout, narrow))
    return plain
