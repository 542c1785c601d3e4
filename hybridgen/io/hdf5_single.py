"""The default HDF5 output (docs/conventions.md section 4): one file, every pass a dataset with a leading
keypoint axis.

Over 300 lines: one writer owns its file, its compressor pool and its writer thread from begin to commit or abort.

Chunks hold one keypoint each. Passes are stored compactly by default (``encoding="compact"``: ids in the
smallest integer type, octahedral uint16 normals, distance derived from depth - see
:mod:`hybridgen.io.label_encoding`, whose :func:`~hybridgen.io.label_encoding.decode_dataset` reads them
back); ``encoding="plain"`` stores the documented dtypes as they are.

Writing never blocks the render thread: each pass of a keypoint is encoded, byte-shuffled (float passes)
and deflated on a thread pool (numpy and ISA-L / zlib release the GIL), while one writer thread stores the finished
chunks in keypoint order with ``write_direct_chunk`` - bit-identical to what HDF5's shuffle + gzip filters
make, so any HDF5 reader opens the file, and the file's bytes do not depend on thread timing. The writer thread
hashes each chunk as it stores it, so sealing the file (``content_sha256``) reads nothing back. The file is
written under a temporary name and renamed only when complete.
"""
from __future__ import annotations

import errno
import json
import os
import queue
import threading
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..config.options import checked_options, option
from ..errors import InputError, fault_errno, fault_message
from .atomic import close_discarded_hdf5, commit, discard, prepare_output_dir, temporary_path
from .blosc2_chunks import Blosc2Chunks
from .chunk_codecs import blosc2_chunks, deflate, shuffled
from .frame_sink import PassLayout
from .hdf5_filters import READ_HINT
from .integrity import ChunkStream, seal
from .label_encoding import (DERIVED_DISTANCE, NARROWED, OCTAHEDRAL, EncodedArray, StoredPass, plan_storage,
                             storage_tag)

COMPRESSIONS = ("gzip", "blosc2", "lzf", "none")
ENCODINGS = ("compact", "plain")
__all__ = ["COMPRESSIONS", "ENCODINGS", "Hdf5Options", "Hdf5SingleFileWriter", "deflate", "shuffled"]
_STOP = object()


def _tag(stored: StoredPass, layout: PassLayout) -> str | None:
    """The storage tag of a pass stored encoded (octahedral normals, narrowed ids, ``derived_from_depth``: not
    stored at all), None otherwise."""
    encoding = stored.attrs.get("encoding")
    if stored.encode is None and encoding == DERIVED_DISTANCE:
        return DERIVED_DISTANCE  # a renderer need not compute it
    if stored.encode is None or encoding not in (OCTAHEDRAL, NARROWED):
        return None
    return storage_tag(encoding, stored.dtype, np.dtype(layout.dtype))


class _UnknownStream(ChunkStream):
    """A dataset whose stored chunks the writer did not see (filtered by HDF5): the seal reads them."""

    def add(self, offset: tuple[int, ...], mask: int, data: Any) -> None:
        pass

    def hexdigest(self) -> str | None:
        return None


_UNKNOWN = _UnknownStream()


def default_threads() -> int:
    """Compressor threads: the cores left over by the render thread (at least one)."""
    return max(1, (os.cpu_count() or 2) - 1)


_TEXT_TYPE = h5py.h5t.py_create(h5py.string_dtype())
_ONE_ELEMENT = h5py.h5s.create_simple((1,))


def _write_text(dset: h5py.Dataset, index: int, text: str) -> None:
    """``dset[index] = text`` for a 1-D variable-length string dataset, through the low-level API (the same
    bytes in the file, a quarter of the time: it runs once per keypoint and JSON pass)."""
    space = dset.id.get_space()
    space.select_hyperslab((index,), (1,))
    dset.id.write(_ONE_ELEMENT, space, np.array([text], dtype=object), _TEXT_TYPE)


@dataclass(frozen=True)
class Hdf5Options:
    """How ``data.hdf5`` stores its datasets, declared once: writer.Hdf5Writer's parameters are these
    (:func:`~hybridgen.config.options.option_params`)."""

    compression: str = option("gzip", "str", "dataset compression: gzip (any HDF5 reader), blosc2 (single layout: "
                              "depth byte-shuffled and LZ4-compressed by Blosc2 without a process-wide lock, the "
                              "other passes gzip: ~20 % less writer CPU, 10-15 % more bytes, no faster end to end "
                              "on 2 cores; plain h5py readers need hdf5plugin: pip install hdf5plugin, then import "
                              "hdf5plugin before opening the file), lzf, none", choices=COMPRESSIONS)
    encoding: str = option("compact", "str", "single layout: compact (ids in the smallest integer type, normals "
                           "octahedral uint16 within 1e-4 rad, distance derived from depth; read them with "
                           "hybridgen.data or hybridgen.io.label_encoding.decode_dataset, docs/outputs.md) or plain "
                           "(the documented dtypes as they are); the blenderproc layout always stores BlenderProc's "
                           "encodings", choices=ENCODINGS)
    compression_level: int = option(1, "int", "gzip (blosc2: its clevel) level 0..9 (1: twice as fast as 4, files "
                                    "~10 % larger)",
                                    check=lambda v: None if 0 <= v <= 9 else f"must be in 0..9, got {v}")


class Hdf5SingleFileWriter:
    """Streams keypoint records into ``path`` (a :class:`~hybridgen.io.frame_sink.FrameSink`).

    Use :meth:`finalize` to add scene-level records and commit, :meth:`abort` to drop the partial file.
    """

    def __init__(self, path: str | Path, options: Hdf5Options | None = None, *, threads: int | None = None,
                 queue_size: int = 3, **given: Any) -> None:
        """``options`` (validated where they were made), or the :class:`Hdf5Options` ``given`` by name
        (``compression=``, ``compression_level=``, ``encoding=``; validated here)."""
        if options is not None and given:
            raise TypeError("give Hdf5SingleFileWriter either options or single options, not both")
        opts = options if options is not None else checked_options(Hdf5Options, **given)
        self.path = Path(path)
        prepare_output_dir(self.path.parent)
        self.compression = opts.compression
        self.level = int(opts.compression_level)
        self.encoding = opts.encoding
        self.threads = default_threads() if threads is None else max(1, int(threads))
        self._temp = temporary_path(self.path)
        self._file: h5py.File | None = None
        self._layouts: dict[str, PassLayout] = {}
        self._stored: dict[str, StoredPass] = {}
        self._datasets: dict[str, h5py.Dataset] = {}  # looked up once: h5[key] costs ~70 us per call
        # Every other dataset made, held open until the file closes: a dataset whose last handle goes closes
        # at once, and on a full disk that close fails half-way (HDF5 then crashed closing the file).
        self._held: list[h5py.Dataset] = []
        self._streams: dict[str, ChunkStream] = {}  # chunked datasets' chunks, hashed as stored (the seal's)
        self._blosc2: dict[str, Blosc2Chunks] = {}  # passes stored through the Blosc2 filter
        self._pool: ThreadPoolExecutor | None = None
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=queue_size)
        self._thread: threading.Thread | None = None
        self._error: BaseException | None = None
        self.frames_written = 0

    # ------------------------------------------------------------------ FrameSink
    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        """Create the datasets of one renderer's passes and store the camera records (checked if present)."""
        self._drain()
        h5 = self._open()
        for layout in layouts:
            if layout.key in h5:
                raise InputError(f"output key '{layout.key}' is produced twice (two renderers write it)")
        self._layouts.update({layout.key: layout for layout in layouts})
        for layout in layouts:
            self._create(h5, layout, n_keypoints)
        for key, value in camera_records.items():
            if key in h5:
                if not np.array_equal(h5[key][()], value):
                    raise InputError(f"'{key}' differs between two renderers of the same run")
            else:
                self._held.append(h5.create_dataset(key, data=value, track_times=False))
        for key, value in attributes.items():
            h5.attrs[key] = value
        if self._pool is None:
            self._pool = ThreadPoolExecutor(self.threads, thread_name_prefix="hdf5-compress")
        self._thread = threading.Thread(target=self._work, name="hdf5-writer", daemon=True)
        self._thread.start()

    def write(self, index: int, values: dict[str, Any]) -> None:
        """Queue keypoint ``index``'s values (arrays or JSON-ready objects): their chunks are made on the
        thread pool now and stored in keypoint order by the writer thread."""
        self._raise_worker_error()
        assert self._pool is not None, "write() before begin()"
        jobs: dict[str, Any] = {}
        for key, value in values.items():
            if self._layouts[key].dtype == "json":
                jobs[key] = value
            else:
                jobs[key] = self._pool.submit(self._chunk, key, index, value)
        self._queue.put((index, jobs))

    def end(self) -> None:
        """Wait until every queued keypoint is written."""
        self._drain()

    def accepted_encodings(self) -> dict[str, str]:
        """Output key -> the storage tag (:func:`~hybridgen.io.label_encoding.storage_tag`) of each pass this
        file stores encoded (asked after ``begin``): a renderer may hand such a pass over already in that form
        (an :class:`~hybridgen.io.label_encoding.EncodedArray`), which is then stored as it is."""
        tags = {key: _tag(stored, self._layouts[key]) for key, stored in self._stored.items()}
        return {key: tag for key, tag in tags.items() if tag is not None}

    # ------------------------------------------------------------------ commit
    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        """Add JSON records (e.g. ``object_states``) and attributes, close, and rename to the final name;
        returns ``[path]``."""
        self._drain()
        h5 = self._open()
        for key, value in (records or {}).items():
            self._held.append(h5.create_dataset(key, data=json.dumps(value), dtype=h5py.string_dtype(),
                                                track_times=False))
        for key, value in (attributes or {}).items():
            h5.attrs[key] = value
        seal(h5, self._streams)  # content_sha256: resume and readers verify the file with it (flushes)
        self._file = None  # a close that fails is never tried again (abort): see close_discarded_hdf5
        h5.close()
        self._held.clear()
        self._shutdown_pool()
        commit(self._temp, self.path)
        return [self.path]

    def abort(self) -> None:
        """Stop writing and delete the temporary file; nothing appears under the final name."""
        try:
            self._drain()
        except BaseException:
            pass
        if self._file is not None:
            close_discarded_hdf5(self._file)  # its flush cannot fail on a full disk and crash HDF5
            self._file = None
        self._datasets.clear()
        self._held.clear()
        self._shutdown_pool()
        discard(self._temp)

    # ------------------------------------------------------------------ internals
    def _open(self) -> h5py.File:
        if self._file is None:
            try:
                self._file = h5py.File(self._temp, "w", libver="v110")
            except OSError as exc:
                if fault_errno(exc) in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):  # the run's line for a full disk
                    raise OSError(fault_errno(exc), os.strerror(fault_errno(exc) or 0), str(self._temp)) from None
                raise InputError(f"cannot write '{self._temp.parent}': "
                                 f"{fault_message(exc) or str(exc).splitlines()[0]}") from None
        return self._file

    def _shutdown_pool(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def _create(self, h5: h5py.File, layout: PassLayout, n: int) -> None:
        if layout.dtype == "json":
            self._datasets[layout.key] = h5.create_dataset(layout.key, shape=(n,), dtype=h5py.string_dtype(),
                                                           track_times=False)
            return
        depth = self._layouts.get("depth")  # distance is derived from depth when its background allows
        background = depth.background if depth is not None and depth.background is not None else np.inf
        stored = plan_storage(layout, compact=self.encoding == "compact", keys=set(self._layouts),
                              depth_background=background)
        self._stored[layout.key] = stored
        options: dict[str, Any] = {}
        if stored.encode is None:  # derived on read: no chunk is ever written; a plain read gives NaN
            options = {"fillvalue": np.nan}
        elif self.compression == "blosc2" and (codec := blosc2_chunks(stored, self.level)) is not None:
            self._blosc2[layout.key] = codec
            options = codec.dataset_options()
            h5.attrs["filters_needed"] = READ_HINT
        elif self.compression in ("gzip", "blosc2"):
            options = {"compression": "gzip", "compression_opts": self.level, "shuffle": stored.shuffle}
        elif self.compression == "lzf":
            options = {"compression": "lzf", "shuffle": stored.shuffle}
        dset = h5.create_dataset(layout.key, shape=(n, *stored.shape), dtype=stored.dtype,
                                 chunks=(1, *stored.shape), track_times=False, **options)
        for name, value in stored.attrs.items():
            dset.attrs[name] = value
        self._datasets[layout.key] = dset
        self._streams[layout.key] = ChunkStream()

    def _chunk(self, key: str, index: int, value: Any) -> np.ndarray | bytes | None:
        """Keypoint ``index``'s stored chunk of ``key`` (runs on the pool): the encoded array, or for gzip
        the shuffled and deflated bytes (Blosc2: its frame); None when the pass is derived on read."""
        layout, stored = self._layouts[key], self._stored[key]
        if isinstance(value, EncodedArray) and value.tag != _tag(stored, layout):
            value = value.decode()  # a form this file does not store
        if isinstance(value, EncodedArray):  # already the stored form (drawn so by the raster pass)
            if stored.encode is None:
                return None  # derived on read: the renderer made no values, none are stored
            if value.stored.shape != stored.shape or value.stored.dtype != stored.dtype:
                raise InputError(f"'{key}' keypoint {index} holds {value.stored.dtype} {value.stored.shape}, "
                                 f"expected {stored.dtype} {stored.shape}")
            encoded = np.ascontiguousarray(value.stored)
        else:
            array = np.asarray(value)
            if array.shape != layout.shape:
                raise InputError(f"'{key}' keypoint {index} has shape {array.shape}, expected {layout.shape}")
            if stored.encode is None:
                return None
            encoded = stored.encode(array)
        codec = self._blosc2.get(key)
        if codec is not None:
            return codec.encode(encoded)
        if self.compression in ("gzip", "blosc2"):
            return deflate(shuffled(encoded) if stored.shuffle else encoded, self.level)
        return encoded

    def _work(self) -> None:
        h5 = self._file
        assert h5 is not None
        while True:
            item = self._queue.get()
            if item is _STOP:
                return
            if self._error is not None:
                continue  # keep draining so producers never block
            try:
                self._store(h5, *item)
            except BaseException as exc:  # surfaced to the producer thread
                self._error = exc

    def _store(self, h5: h5py.File, index: int, jobs: dict[str, Any]) -> None:
        """Store keypoint ``index``: per key a JSON value, or its chunk (a Future of it, or the chunk itself:
        bytes, an array, None for a pass derived on read)."""
        for key, job in jobs.items():
            dset = self._datasets[key]
            if self._layouts[key].dtype == "json":
                _write_text(dset, index, json.dumps(job))
                continue
            chunk = job.result() if isinstance(job, Future) else job
            if chunk is None:
                continue
            if isinstance(chunk, bytes) or self.compression == "none":
                # gzip, blosc2: compressed bytes; none: the array's bytes are the chunk as HDF5 stores it
                offset = (index,) + (0,) * len(self._stored[key].shape)
                dset.id.write_direct_chunk(offset, chunk)
                self._streams[key].add(offset, 0, chunk)
            else:  # HDF5 filters it (lzf): the stored bytes are read back by the seal
                dset[index] = chunk
                self._streams[key] = _UNKNOWN
        self.frames_written += 1

    def _drain(self) -> None:
        if self._thread is not None:
            self._queue.put(_STOP)
            self._thread.join()
            self._thread = None
        self._raise_worker_error()

    def _raise_worker_error(self) -> None:
        if self._error is not None:
            error, self._error = self._error, None
            raise error
