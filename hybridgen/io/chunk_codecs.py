"""The byte-level codecs of the HDF5 writer's chunks, applied on its compressor threads: deflate (ISA-L or zlib,
HDF5's gzip filter), HDF5's byte shuffle, and the Blosc2 codec of the float passes."""
from __future__ import annotations

import threading
import zlib
from typing import Any

import numpy as np

from .blosc2_chunks import Blosc2Chunks
from .label_encoding import StoredPass

def deflate(data: Any, level: int) -> bytes:
    """A zlib-format stream of ``data`` (what HDF5's gzip filter reads). Levels 1-3 use ISA-L (``isal``, a
    dependency: 4-6x faster than zlib at the same ratio) for inputs of :data:`ISAL_MIN_BYTES` or more, 0 and 4-9
    and smaller inputs zlib's own. The bytes differ between the two libraries, never between runs: ISA-L calls
    are serialized by a process-wide lock because concurrent calls occasionally pick other matches - valid
    streams of the same data but other bytes (measured: 2 of 320 compressions of one 192-byte segmap by 8
    threads at once; 0 of 480 under the lock; it made resumed runs differ from direct ones at random). One
    ISA-L call at a time (~400 MB/s on one core here) still outpaces the label pass; the compressor threads
    overlap everything else."""
    if 1 <= level <= 3 and _isal is not None and memoryview(data).nbytes >= ISAL_MIN_BYTES:
        with _ISAL_LOCK:
            return _isal.compress(data, level)
    return zlib.compress(data, level)


ISAL_MIN_BYTES = 16384
"""Smaller inputs are deflated by zlib: ISA-L gave other (valid) streams for the same small input even under the
lock - the 192-byte id maps of a 16x12 test run compressed to 42 or 43 bytes from run to run in one long process
under load (session 6: resumed and direct files differed by a few bytes, about 1 run in 5-20) - and zlib costs
nothing at these sizes. Every image of 128x128 pixels or more still goes through ISA-L."""


_ISAL_LOCK = threading.Lock()


try:
    from isal import isal_zlib as _isal
except ImportError:  # pragma: no cover - isal is a dependency; zlib is the fallback of a partial install
    _isal = None


def blosc2_chunks(stored: StoredPass, level: int) -> Blosc2Chunks | None:
    """The Blosc2 codec of a pass under ``compression: blosc2``: LZ4 at ``level`` over the byte-shuffled float
    passes (depth: 0.5-0.63x ISA-L's CPU with the shuffle, ~18 % more bytes); None where deflate stays - the
    octahedral normal codes (LZ4 gave 1.2-2.6x the bytes for 0.5-0.75x the CPU) and the id maps (LZ4 gave twice
    the bytes at the same speed; tools/bench_writer.py, docs/label_pipeline.md)."""
    if not stored.shuffle:
        return None
    return Blosc2Chunks("lz4", level, "byte", stored.dtype.itemsize)


def shuffled(array: np.ndarray) -> np.ndarray:
    """The bytes HDF5's shuffle filter makes of a contiguous ``array``: byte k (in memory order) of every element
    together, as an (itemsize, size) uint8 array. Elements of 2, 4 or 8 bytes are read as little-endian words and
    each plane is one shift-and-narrow pass over them (0.19 instead of 0.30 ms for a 640x480 float32 image as a
    strided transpose)."""
    size = array.itemsize
    if size == 1:
        return array
    flat = np.ascontiguousarray(array).reshape(-1)
    if size not in (2, 4, 8):
        return np.ascontiguousarray(flat.view(np.uint8).reshape(-1, size).T)
    words = flat.view(f"<u{size}")  # memory byte k of an element = bits 8k..8k+7 of its little-endian word
    planes = np.empty((size, words.size), np.uint8)
    for k in range(size):
        np.right_shift(words, 8 * k, out=planes[k], casting="unsafe")  # the cast keeps the low 8 bits
    return planes
