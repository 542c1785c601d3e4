"""The default HDF5 output (docs/conventions.md section 4): one file, every pass a dataset with a leading keypoint axis.

Chunks hold one keypoint each. Writing happens on a background thread, so keypoint i+1 renders while
keypoint i is compressed (zlib releases the GIL) and written: gzip chunks are deflated here and stored
with ``write_direct_chunk``, bit-identical to what HDF5's own gzip filter makes. The file is written under
a temporary name and renamed only when complete.
"""
from __future__ import annotations

import json
import queue
import threading
import zlib
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..errors import InputError
from .atomic import commit, prepare_output_dir, temporary_path
from .frame_sink import PassLayout
from .integrity import seal

COMPRESSIONS = ("gzip", "lzf", "none")
_STOP = object()


class Hdf5SingleFileWriter:
    """Streams keypoint records into ``path`` (a :class:`~hybridgen.io.frame_sink.FrameSink`).

    Use :meth:`finalize` to add scene-level records and commit, :meth:`abort` to drop the partial file.
    """

    def __init__(self, path: str | Path, *, compression: str = "gzip", compression_level: int = 1,
                 queue_size: int = 3) -> None:
        if compression not in COMPRESSIONS:
            raise InputError(f"compression must be one of {COMPRESSIONS}, got {compression!r}")
        self.path = Path(path)
        prepare_output_dir(self.path.parent)
        self.compression = compression
        self.level = int(compression_level)
        self._temp = temporary_path(self.path)
        self._file: h5py.File | None = None
        self._layouts: dict[str, PassLayout] = {}
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
            self._create(h5, layout, n_keypoints)
            self._layouts[layout.key] = layout
        for key, value in camera_records.items():
            if key in h5:
                if not np.array_equal(h5[key][()], value):
                    raise InputError(f"'{key}' differs between two renderers of the same run")
            else:
                h5.create_dataset(key, data=value, track_times=False)
        for key, value in attributes.items():
            h5.attrs[key] = value
        self._thread = threading.Thread(target=self._work, name="hdf5-writer", daemon=True)
        self._thread.start()

    def write(self, index: int, values: dict[str, Any]) -> None:
        """Queue keypoint ``index``'s values (arrays or JSON-ready objects) for writing."""
        self._raise_worker_error()
        self._queue.put((index, values))

    def end(self) -> None:
        """Wait until every queued keypoint is written."""
        self._drain()

    # ------------------------------------------------------------------ commit
    def finalize(self, records: dict[str, Any] | None = None, attributes: dict[str, Any] | None = None) -> Path:
        """Add JSON records (e.g. ``object_states``) and attributes, close, and rename to the final name."""
        self._drain()
        h5 = self._open()
        for key, value in (records or {}).items():
            h5.create_dataset(key, data=json.dumps(value), dtype=h5py.string_dtype(), track_times=False)
        for key, value in (attributes or {}).items():
            h5.attrs[key] = value
        seal(h5)  # content_sha256: resume and readers verify the file with it
        h5.close()
        self._file = None
        commit(self._temp, self.path)
        return self.path

    def abort(self) -> None:
        """Stop writing and delete the temporary file; nothing appears under the final name."""
        try:
            self._drain()
        except BaseException:
            pass
        if self._file is not None:
            try:
                self._file.close()
            except Exception:
                pass
            self._file = None
        self._temp.unlink(missing_ok=True)

    # ------------------------------------------------------------------ internals
    def _open(self) -> h5py.File:
        if self._file is None:
            try:
                self._file = h5py.File(self._temp, "w", libver="v110")
            except OSError as exc:
                raise InputError(f"cannot write '{self._temp.parent}': {exc}") from None
        return self._file

    def _create(self, h5: h5py.File, layout: PassLayout, n: int) -> None:
        if layout.dtype == "json":
            h5.create_dataset(layout.key, shape=(n,), dtype=h5py.string_dtype(), track_times=False)
            return
        options: dict[str, Any] = {}
        if self.compression == "gzip":
            options = {"compression": "gzip", "compression_opts": self.level}
        elif self.compression == "lzf":
            options = {"compression": "lzf"}
        h5.create_dataset(layout.key, shape=(n, *layout.shape), dtype=layout.dtype,
                          chunks=(1, *layout.shape), track_times=False, **options)

    def _work(self) -> None:
        h5 = self._file
        assert h5 is not None
        while True:
            item = self._queue.get()
            if item is _STOP:
                return
            if self._error is not None:
                continue  # keep draining so producers never block
            index, values = item
            try:
                for key, value in values.items():
                    self._store(h5[key], self._layouts[key], index, value)
                self.frames_written += 1
            except BaseException as exc:  # surfaced to the producer thread
                self._error = exc

    def _store(self, dset: h5py.Dataset, layout: PassLayout, index: int, value: Any) -> None:
        if layout.dtype == "json":
            dset[index] = json.dumps(value)
            return
        array = np.ascontiguousarray(value, dtype=layout.dtype)
        if array.shape != layout.shape:
            raise InputError(f"'{layout.key}' keypoint {index} has shape {array.shape}, expected {layout.shape}")
        if self.compression == "gzip":
            dset.id.write_direct_chunk((index,) + (0,) * len(layout.shape), zlib.compress(array, self.level))
        else:
            dset[index] = array

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
