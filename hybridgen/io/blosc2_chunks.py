"""Chunks of HDF5's Blosc2 filter (id 32026, hdf5plugin), made outside HDF5 for ``write_direct_chunk``.

What the filter reads (hdf5-blosc2's ``blosc2_filter.c``, decompression branch): the stored chunk is a Blosc2
super-chunk serialized as a contiguous frame (``blosc2_schunk_from_buffer``); without a ``b2nd`` metalayer
its first chunk is decompressed whole, its size taken from that chunk's header. So a one-chunk
:class:`blosc2.SChunk` holding the array's bytes, as ``to_cframe()``, is exactly such a chunk; the filter's
own compression makes the same kind of frame (or a b2nd one for chunks of rank 2-8; both decode).

Bytes are deterministic: one thread per compression (Blosc2's own threads place finished blocks in the
order they finish), the same codec, level, filter and block size, and the frame header's fields fixed by
them; c-blosc2's ``BLOSC_*`` environment overrides are refused (:func:`_one_thread_contexts`). They can change
with the Blosc2 format version, as deflate's bytes can with the zlib/ISA-L version.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from ..errors import InputError

CODECS = {"blosclz": 0, "lz4": 1, "lz4hc": 2, "zlib": 4, "zstd": 5}
"""Blosc2 codec names -> the filter's compcode (cd_values[6])."""
SHUFFLES = {"none": 0, "byte": 1, "bit": 2}
"""Blosc2 filters before the codec -> the filter's doshuffle (cd_values[5])."""


OVERRIDING_ENVIRONMENT = ("BLOSC_BLOCKSIZE", "BLOSC_CLEVEL", "BLOSC_COMPRESSOR", "BLOSC_DELTA", "BLOSC_SHUFFLE",
                          "BLOSC_SPLITMODE", "BLOSC_TYPESIZE")
"""Variables c-blosc2 reads whenever it makes a compression context (``blosc2_create_cctx``), overriding the
parameters given: with any of them set, the chunks would not be the codec this file records."""


def _blosc2() -> Any:
    try:
        import blosc2
    except ImportError:
        raise InputError("compression 'blosc2' needs the blosc2 package: pip install blosc2 "
                         "(or pip install 'hybridgen[blosc2]')") from None
    blosc2.set_releasegil(True)  # compress on the writer's pool threads while the render thread runs
    _one_thread_contexts()
    return blosc2


def _one_thread_contexts() -> None:
    """Every Blosc2 context of this process gets one thread (``BLOSC_NTHREADS=1``, which c-blosc2 reads at
    context creation). Our chunks ask for one thread anyway (with more, Blosc2 places compressed blocks in the
    order they finish: other bytes), but serializing a frame compresses its offsets with a context of 4
    threads that c-blosc2 makes itself (``frame.c``): it started and joined 4 threads for every chunk, ~1-3 ms
    of wall time per frame for 0.1 ms of work (measured here, 2 cores, under load). The writer's pool is the
    parallelism."""
    given = [name for name in OVERRIDING_ENVIRONMENT if os.environ.get(name)]
    threads = os.environ.get("BLOSC_NTHREADS")
    if threads not in (None, "", "1"):
        given.append("BLOSC_NTHREADS")
    if given:
        raise InputError(f"compression 'blosc2': unset the environment variable(s) {', '.join(given)}: c-blosc2 "
                         "lets them override the codec, level, shuffle and threads hybridgen asks for, so the "
                         "stored bytes would depend on them")
    os.environ["BLOSC_NTHREADS"] = "1"


@dataclass(frozen=True)
class Blosc2Chunks:
    """One dataset's Blosc2 codec: ``codec`` (a :data:`CODECS` name), ``level`` (0-9), ``shuffle`` (a
    :data:`SHUFFLES` name, applied over items of ``typesize`` bytes)."""

    codec: str
    level: int
    shuffle: str
    typesize: int

    def dataset_options(self) -> dict[str, Any]:
        """``h5py.create_dataset`` keywords of the filter (hdf5plugin fills in the rest when it is set)."""
        from .hdf5_filters import BLOSC2_FILTER_ID, enable_filters

        enable_filters()
        return {"compression": BLOSC2_FILTER_ID,
                "compression_opts": (0, 0, 0, 0, self.level, SHUFFLES[self.shuffle], CODECS[self.codec])}

    def _cparams(self) -> dict[str, Any]:
        blosc2 = _blosc2()
        shuffle = {"none": blosc2.Filter.NOFILTER, "byte": blosc2.Filter.SHUFFLE,
                   "bit": blosc2.Filter.BITSHUFFLE}[self.shuffle]
        return {"codec": blosc2.Codec(CODECS[self.codec]), "clevel": self.level, "filters": [shuffle],
                "filters_meta": [0], "typesize": self.typesize, "nthreads": 1}

    def encode(self, data: Any) -> bytes:
        """The stored chunk of ``data`` (a contiguous array or buffer): a one-chunk super-chunk frame."""
        blosc2 = _blosc2()
        view = memoryview(data).cast("B")
        schunk = blosc2.SChunk(chunksize=view.nbytes, cparams=self._cparams(), dparams={"nthreads": 1})
        schunk.append_data(view)
        return bytes(schunk.to_cframe())
