"""The two on-disk layouts a :class:`~hybridgen.data.reader.KeypointDataset` reads, behind one interface.

- :class:`SingleFileLayout`: ``data.hdf5`` with a leading keypoint axis per key (docs/conventions.md,
  HDF5 layout), either written directly or as the index of a sharded run (HDF5 virtual datasets over
  ``shards/*.hdf5``, plus ``scene_index``/``keypoint_index`` and per-scene ``object_states``/``light_states``).
- :class:`BlenderProcLayout`: one ``<i>.hdf5`` per keypoint (``writer.Hdf5Writer`` with ``layout:
  blenderproc``): BlenderProc's keys and encodings, decoded back to hybridgen's (normals, ``cam_states``).

Both return, per keypoint, ``{key: numpy array or decoded JSON}`` plus ``scene_index``/``keypoint_index``.
A layout object holds no open file: :meth:`open` returns a handle the reader keeps per process.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Sequence

import h5py
import numpy as np

from ..errors import InputError
from ..io.hdf5_filters import enable_filters
from ..render.passes import RECORDS, exact
from .decode import blenderproc_camera, blenderproc_normals, decode_attribute, decode_text

SCENE_RECORDS = tuple(key for key, kind in RECORDS.items() if kind == "scene")
POSITION_KEYS = tuple(key for key, kind in RECORDS.items() if kind == "position")
_NUMBERED = re.compile(r"(\d+)\.hdf5")


def open_hdf5(path: Path) -> h5py.File:
    """``path`` opened read-only (hdf5plugin's filters registered first: ``compression: blosc2`` files); an
    InputError naming it when it is missing or not HDF5."""
    enable_filters()
    try:
        return h5py.File(path, "r")
    except FileNotFoundError:
        raise InputError(f"'{path}' does not exist") from None
    except OSError as exc:
        raise InputError(f"cannot open '{path}' as HDF5: {exc}") from None


def _is_single_file(h5: h5py.File) -> bool:
    cam_K = h5.get("cam_K")
    return isinstance(cam_K, h5py.Dataset) and cam_K.ndim == 3


class SingleFileLayout:
    """``data.hdf5`` (plain or a sharded run's index)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._cache: dict[str, h5py.Dataset] = {}
        self._cache_for: h5py.File | None = None
        with self.open() as h5:
            if not _is_single_file(h5):
                raise InputError(f"'{path}' is not a hybridgen data file: it has no 'cam_K' (N, 3, 3) dataset")
            self.count = int(h5["cam_K"].shape[0])
            self.sharded = "scene_index" in h5 and any(h5[k].ndim == 1 for k in SCENE_RECORDS if k in h5)
            self.keys = [k for k, d in h5.items() if isinstance(d, h5py.Dataset) and d.ndim >= 1
                         and d.shape[0] == self.count and k not in SCENE_RECORDS + POSITION_KEYS]
            self.text_keys = {k for k in self.keys if h5py.check_string_dtype(h5[k].dtype) is not None}
            self.encoded = {k for k in self.keys if "encoding" in h5[k].attrs}  # compact storage, decoded on read
            self.scene_keys = [k for k in SCENE_RECORDS if k in h5]
            self.attributes = {k: decode_attribute(v) for k, v in h5.attrs.items()}
            scenes = [int(s) for s in np.unique(h5["scene_index"][()])] if self.sharded else [0]
            self.scene_slot = {scene: slot for slot, scene in enumerate(scenes)}  # row of the per-scene records

    def open(self) -> h5py.File:
        """The file, after checking that every shard its virtual datasets read exists and is the one the
        index was built over (virtual datasets over missing shards would read fill values silently)."""
        from ..run.shard_index import check_index_sources

        h5 = open_hdf5(self.path)
        try:
            check_index_sources(self.path, h5)
        except BaseException:
            h5.close()
            raise
        return h5

    def _datasets(self, h5: h5py.File) -> dict[str, h5py.Dataset]:
        """The datasets of the open file ``h5`` by name (looked up once per handle: h5py lookups are slow)."""
        if self._cache_for is not h5:
            self._cache = {k: v for k, v in h5.items() if isinstance(v, h5py.Dataset)}
            self._cache_for = h5
        return self._cache

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_cache": {}, "_cache_for": None}

    def position(self, h5: h5py.File, index: int) -> tuple[int, int]:
        """(scene_index, keypoint_index) of keypoint ``index``."""
        datasets = self._datasets(h5)
        scene = int(datasets["scene_index"][index]) if "scene_index" in datasets else 0
        keypoint = int(datasets["keypoint_index"][index]) if "keypoint_index" in datasets else index
        return scene, keypoint

    def read(self, h5: h5py.File, index: int, keys: Sequence[str]) -> dict[str, Any]:
        """Keypoint ``index``'s ``keys`` (per-keypoint keys and scene records)."""
        scene, keypoint = self.position(h5, index)
        datasets = self._datasets(h5)
        item: dict[str, Any] = {}
        for key in keys:
            dset = datasets[key]
            if key in SCENE_RECORDS:
                item[key] = decode_text(dset[self.scene_slot[scene]] if dset.ndim else dset[()])
            elif key in self.text_keys:
                item[key] = decode_text(dset[index])
            elif key in self.encoded:
                from ..io.label_encoding import decode_dataset

                item[key] = decode_dataset(dset, index)
            else:
                item[key] = dset[index]
        item["scene_index"], item["keypoint_index"] = scene, keypoint
        return item


class BlenderProcLayout:
    """``<i>.hdf5`` files, one per keypoint, read in the order of ``i``."""

    def __init__(self, files: Sequence[Path]) -> None:
        if not files:
            raise InputError("no <i>.hdf5 files to read")
        self.files = list(files)
        self.count = len(self.files)
        self.sharded = False
        with open_hdf5(self.files[0]) as h5:
            if _is_single_file(h5):
                raise InputError(f"'{self.files[0]}' is a single data file (keypoint axis first), not a "
                                 "BlenderProc per-keypoint file; open it on its own")
            stored = [k for k, d in h5.items() if isinstance(d, h5py.Dataset) and k != "hybridgen_version"]
            self.attributes = {k: decode_attribute(v) for k, v in h5.attrs.items()}
            if "hybridgen_version" in h5:
                self.attributes.setdefault("hybridgen_version", decode_text(h5["hybridgen_version"][()]))
        self.scene_keys = [k for k in SCENE_RECORDS if k in stored]
        self.keys = [k for k in stored if k not in SCENE_RECORDS]
        if "cam_states" in self.keys:
            self.keys += ["cam_K", "cam2world"]

    def open(self) -> None:
        """Nothing stays open: each keypoint is its own file."""
        return None

    def position(self, h5: Any, index: int) -> tuple[int, int]:
        match = _NUMBERED.fullmatch(self.files[index].name)
        return 0, int(match.group(1)) if match else index

    def read(self, h5: Any, index: int, keys: Sequence[str]) -> dict[str, Any]:
        item: dict[str, Any] = {}
        with open_hdf5(self.files[index]) as f:
            state = decode_text(f["cam_states"][()]) if "cam_states" in f else None
            camera = blenderproc_camera(state) if isinstance(state, dict) else {}
            for key in keys:
                if key in camera:
                    item[key] = camera[key]
                    continue
                if key not in f:
                    raise InputError(f"'{self.files[index]}' has no key '{key}' (the other files of this dataset do)")
                value = f[key][()]
                if isinstance(value, (bytes, np.bytes_)) or f[key].dtype.kind in ("S", "O"):
                    item[key] = decode_text(value)
                elif _blenderproc_normals(key) and "cam2world" in camera:
                    item[key] = blenderproc_normals(value, camera["cam2world"],
                                                    str(self.attributes.get("normals_space", "camera")))
                else:
                    item[key] = value
        item["scene_index"], item["keypoint_index"] = self.position(None, index)
        return item


def _blenderproc_normals(key: str) -> bool:
    entry = exact(key)
    return entry is not None and entry.blenderproc == "blender_half_unit"


def numbered_files(folder: Path) -> list[Path]:
    """``<i>.hdf5`` files of ``folder`` in the order of ``i``."""
    found = [(int(m.group(1)), p) for p in folder.glob("*.hdf5") if (m := _NUMBERED.fullmatch(p.name))]
    return [p for _, p in sorted(found)]


def find_layout(source: str | Path | Sequence[str | Path]) -> SingleFileLayout | BlenderProcLayout:
    """The layout of ``source``: a ``data.hdf5``-style file, an output folder (its ``data.hdf5``, else its
    ``<i>.hdf5`` files), one BlenderProc ``<i>.hdf5`` file, or a list of them."""
    if not isinstance(source, (str, Path)):
        return BlenderProcLayout([Path(p) for p in source])
    path = Path(source)
    if path.is_dir():
        if (path / "data.hdf5").is_file():
            return SingleFileLayout(path / "data.hdf5")
        files = numbered_files(path)
        if not files:
            raise InputError(f"'{path}' holds neither data.hdf5 nor BlenderProc <i>.hdf5 files")
        return BlenderProcLayout(files)
    with open_hdf5(path) as h5:
        single = _is_single_file(h5)
    return SingleFileLayout(path) if single else BlenderProcLayout([path])
