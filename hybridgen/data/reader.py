"""``KeypointDataset``: hybridgen's HDF5 outputs as a sequence of per-keypoint dicts of NumPy arrays.

::

    from hybridgen.data import KeypointDataset
    data = KeypointDataset("output/quickstart", keys=["colors", "depth", "instance_segmaps"])
    sample = data[0]   # {"colors": uint8 (H, W, 3), "depth": float32 (H, W), ..., "scene_index": 0, ...}

Every key comes back in the dtype and frame the README's output table gives (docs/conventions.md):
``colors`` uint8 sRGB, ``depth``/``distance`` float32 metres, ``normals`` float32 unit vectors, ids int32,
``cam_K``/``cam2world`` float64 (OpenCV axes); JSON values (``instance_attribute_maps``,
``object_records``, ``object_states``, ``light_states``, ``cam_states``) as Python objects. The BlenderProc
layout is decoded to the same conventions (normals back from ``0.5 n + 0.5`` in Blender axes; ``cam_K``
and ``cam2world`` from ``cam_states``). Each sample also carries ``scene_index`` and ``keypoint_index``.

The object holds no open file when pickled: each process opens the file on first use, so it works as a
PyTorch map-style dataset with ``num_workers > 0`` (:class:`hybridgen.data.TorchKeypointDataset` is the
``torch.utils.data.Dataset`` subclass). A sharded run's ``data.hdf5`` whose shard files are missing raises
one error naming them instead of returning HDF5's fill values.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Iterator, Sequence

from ..errors import InputError
from .layouts import POSITION_KEYS, find_layout


class KeypointDataset:
    """Keypoints of a hybridgen output (``data.hdf5``, a sharded index, or BlenderProc ``<i>.hdf5`` files).

    ``source``: a file, an output folder, or a list of BlenderProc ``<i>.hdf5`` files. ``keys``: the keys
    each sample holds (default: every per-keypoint key and the scene records); unknown keys are an error
    that lists the available ones.
    """

    def __init__(self, source: str | Path | Sequence[str | Path], keys: Sequence[str] | None = None) -> None:
        self.layout = find_layout(source)
        self.available = list(self.layout.keys) + list(self.layout.scene_keys)
        if keys is None:
            self.keys = list(self.available)
        else:
            unknown = [k for k in keys if k not in self.available and k not in POSITION_KEYS]
            if unknown:
                raise InputError(f"{self._where()} has no key(s) {unknown}; available: {self.available}")
            self.keys = [k for k in keys if k not in POSITION_KEYS]
        self._handle: Any = None
        self._pid: int | None = None

    # --------------------------------------------------------------------------- metadata
    @property
    def attributes(self) -> dict[str, Any]:
        """The run's attributes (seed, resolved config text, normals_space, renderer settings, ...)."""
        return dict(self.layout.attributes)

    @property
    def sharded(self) -> bool:
        """Whether this is the index of a sharded run (virtual datasets over ``shards/``)."""
        return self.layout.sharded

    def _where(self) -> str:
        path = getattr(self.layout, "path", None)
        return f"'{path}'" if path is not None else f"'{self.layout.files[0].parent}' (<i>.hdf5 files)"

    # --------------------------------------------------------------------------- sequence
    def __len__(self) -> int:
        return self.layout.count

    def __getitem__(self, index: int) -> dict[str, Any]:
        count = len(self)
        if not isinstance(index, int) and not hasattr(index, "__index__"):
            raise TypeError(f"keypoint index must be an integer, got {type(index).__name__}")
        position = int(index) + (count if int(index) < 0 else 0)
        if not 0 <= position < count:
            raise IndexError(f"keypoint {index} out of range for {count} keypoint(s)")
        try:
            return self.layout.read(self._file(), position, self.keys)
        except OSError as exc:  # a damaged chunk (checksum/filter failure) read past an intact header
            detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise InputError(f"{self._where()}: keypoint {position} cannot be read, the file is damaged "
                             f"({detail})") from None

    def __iter__(self) -> Iterator[dict[str, Any]]:
        for index in range(len(self)):
            yield self[index]

    # --------------------------------------------------------------------------- per-process file handle
    def _file(self) -> Any:
        """This process's open file (opened on first use; a forked or spawned worker opens its own)."""
        if self._pid != os.getpid():
            self._handle = self.layout.open()
            self._pid = os.getpid()
        return self._handle

    def close(self) -> None:
        """Close this process's file handle (reopened on the next access)."""
        if self._handle is not None and self._pid == os.getpid():
            self._handle.close()
        self._handle, self._pid = None, None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_handle"], state["_pid"] = None, None
        return state

    def __enter__(self) -> "KeypointDataset":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"KeypointDataset({self._where()}, {len(self)} keypoint(s), keys={self.keys})"
