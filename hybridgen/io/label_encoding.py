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

from .array_encoding import (DERIVED_DISTANCE, NARROWED, OCTAHEDRAL, OCTAHEDRAL_MAX_ERROR_RAD,  # noqa: F401
                             EncodedArray, decode_octahedral, encode_octahedral, narrowest_integer_dtype,
                             storage_tag)
from .frame_sink import PassLayout


def ray_lengths(K: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W) float32 |((u - cx) / fx, (v - cy) / fy, 1)| per pixel centre (the renderer's own arithmetic)."""
    from ..scene.camera import Intrinsics

    return Intrinsics(np.asarray(K, dtype=np.float64), width, height).pixel_ray_lengths()


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
