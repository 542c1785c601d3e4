"""The run's ``data.hdf5`` over the shards of a sharded run: HDF5 virtual datasets, nothing copied.

Every per-keypoint dataset of the shards (``colors``, ``depth``, ``cam2world``, ...) becomes one virtual
dataset with a leading axis over all keypoints of all scenes, in scene then keypoint order; reading it reads
the shards (HDF5 >= 1.10, which h5py and every current HDF5 tool use; the shards must stay beside it in
``shards/``). Variable-length JSON values (``instance_attribute_maps``) cannot be virtual and are copied.
Added: ``scene_index`` and ``keypoint_index`` (N,) - where each keypoint comes from - and the per-scene
``object_states`` / ``light_states`` (S,) JSON. Built under a temporary name and renamed; no timestamps,
so the same shards give the same bytes.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..errors import InputError
from ..io.atomic import commit, hdf5_temporary, temporary_path
from ..io.integrity import DIGEST_ATTR, seal
from .fingerprint import FINGERPRINT_ATTR

SCENE_RECORDS = ("object_states", "light_states")
UNIT_ATTRIBUTES = ("scene_index", "chunk_index", "scene_keypoints", FINGERPRINT_ATTR, DIGEST_ATTR)
SHARD_DIGESTS_ATTR = "shard_digests"


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def fill_value(dtype: Any) -> np.ndarray | None:
    """What a virtual dataset reads where a source is missing: NaN for floats (never valid data), -1 for
    signed integers (no valid id), nothing special for unsigned ones (every value is valid data: readers
    must call :func:`check_index_sources`)."""
    dtype = np.dtype(dtype)
    if dtype.kind == "f":
        return np.array(np.nan, dtype)
    if dtype.kind == "i":
        return np.array(-1, dtype)
    return None


def _small_metadata_cache(h5: h5py.File, size: int = 1 << 16) -> None:
    """Give ``h5`` a fixed, small metadata cache. HDF5 keeps the decoded layout of every virtual dataset
    whose object header is cached (~4 KB per source file and dataset) but sizes its cache by the encoded
    headers (a few hundred bytes), so an index's datasets all stayed decoded until the file closed: memory
    grew with the number of shards. Evicting early changes no byte of the file."""
    config = h5.id.get_mdc_config()
    config.set_initial_size = True
    config.initial_size = config.min_size = config.max_size = size
    config.incr_mode = config.flash_incr_mode = config.decr_mode = 0  # H5C_incr__off, H5C_flash_incr__off, H5C_decr__off
    h5.id.set_mdc_config(config)


def _virtual(h5: h5py.File, key: str, pieces: list[tuple[str, int, int, tuple[int, ...]]], dtype: Any,
             tail: tuple[int, ...]) -> None:
    """Create ``key`` mapping ``(relative file, offset, count, source shape)`` pieces, without timestamps."""
    total = sum(count for _, _, count, _ in pieces)
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_obj_track_times(False)
    fill = fill_value(dtype)
    if fill is not None:
        dcpl.set_fill_value(fill)
    for filename, offset, count, source_shape in pieces:
        target = h5py.h5s.create_simple((total, *tail))
        target.select_hyperslab((offset,) + (0,) * len(tail), (count, *tail))
        source = h5py.h5s.create_simple(source_shape)
        source.select_all()
        dcpl.set_virtual(target, filename.encode(), key.encode(), source)
    h5py.h5d.create(h5.id, key.encode(), h5py.h5t.py_create(dtype), h5py.h5s.create_simple((total, *tail)),
                    dcpl=dcpl)


@dataclass
class _Shard:
    """What the index needs of one shard, read with only that shard open (an index over 100k shards must
    not hold 100k open files and their caches)."""

    name: str  # relative to the index's folder
    count: int
    scene: int
    digest: str
    layouts: dict[str, tuple[Any, tuple[int, ...]]]  # per-keypoint key -> (dtype, shape)
    strings: dict[str, np.ndarray]  # per-keypoint JSON keys (copied, cannot be virtual)
    records: dict[str, Any]  # SCENE_RECORDS, for a scene's first chunk


def _read_shard(shard: Path, folder: Path, first_of_scene: set[int]) -> _Shard:
    with h5py.File(shard, "r") as f:
        count = len(f["keypoint_index"])
        scene = int(f.attrs["scene_index"])
        layouts, strings = {}, {}
        for key in f:
            dset = f[key]
            if not isinstance(dset, h5py.Dataset) or dset.shape[:1] != (count,) or key in SCENE_RECORDS:
                continue
            if h5py.check_string_dtype(dset.dtype) is not None:
                strings[key] = dset[()]
            layouts[key] = (dset.dtype, dset.shape)
        records = {}
        if scene not in first_of_scene:
            first_of_scene.add(scene)
            records = {key: f[key][()] for key in SCENE_RECORDS if key in f}
        return _Shard(str(Path(shard).relative_to(folder)), count, scene, _text(f.attrs.get(DIGEST_ATTR, "")),
                      layouts, strings, records)


def build_index(path: Path, shards: list[Path], fingerprint: str | None = None) -> Path:
    """Write ``path`` over ``shards`` (already in scene, chunk order); returns ``path``. The index records
    each shard's ``content_sha256`` (attribute ``shard_digests``, JSON: relative path -> digest) and the
    run's ``fingerprint``; it is sealed itself (:func:`hybridgen.io.integrity.seal`). Shards are read one
    at a time."""
    first_of_scene: set[int] = set()
    infos = [_read_shard(shard, path.parent, first_of_scene) for shard in shards]
    with h5py.File(shards[0], "r") as first:
        run_attributes = {k: v for k, v in first.attrs.items() if k not in UNIT_ATTRIBUTES}
        key_attributes = {key: dict(first[key].attrs) for key in infos[0].layouts}
    offsets = np.concatenate([[0], np.cumsum([info.count for info in infos])])
    temp = temporary_path(path)
    held: list[Any] = []  # datasets with data open until the file closes (a lone close on a full disk: atomic.py)
    with hdf5_temporary(temp, libver="v110") as index:
        _small_metadata_cache(index)
        for key, (dtype, shape) in infos[0].layouts.items():
            if key in infos[0].strings:
                values = np.concatenate([info.strings[key] for info in infos])
                held.append(index.create_dataset(key, data=values, dtype=dtype, track_times=False))
                continue
            pieces = [(info.name, int(offsets[i]), info.count, info.layouts[key][1]) for i, info in enumerate(infos)]
            # shards of different scenes may store ids in different narrow types: the widest holds all
            # not held: an open virtual dataset keeps its decoded mapping (~4 KB per shard) in memory
            _virtual(index, key, pieces, np.result_type(*(info.layouts[key][0] for info in infos)), shape[1:])
            for name, value in key_attributes[key].items():  # how the pass is stored (encoding), read by decoders
                index[key].attrs[name] = value
        scenes = np.concatenate([[info.scene] * info.count for info in infos]).astype(np.int64)
        held.append(index.create_dataset("scene_index", data=scenes, track_times=False))
        firsts = sorted((info for info in infos if info.records), key=lambda info: info.scene)
        for key in SCENE_RECORDS:
            if key in infos[0].records:
                held.append(index.create_dataset(key, data=[info.records[key] for info in firsts],
                                                 dtype=h5py.string_dtype(), track_times=False))
        for key, value in run_attributes.items():
            index.attrs[key] = value
        index.attrs["number_of_scenes"] = len(firsts)
        index.attrs["layout"] = "sharded: virtual datasets over shards/*.hdf5"
        index.attrs[SHARD_DIGESTS_ATTR] = json.dumps({info.name: info.digest for info in infos}, sort_keys=True)
        if fingerprint is not None:
            index.attrs[FINGERPRINT_ATTR] = fingerprint
        seal(index)
    commit(temp, path)
    return path


def virtual_sources(h5: h5py.File) -> list[str]:
    """The distinct source file names (as stored, relative to the index's folder) of ``h5``'s virtual datasets."""
    names: dict[str, None] = {}
    for key in h5:
        dset = h5[key]
        if isinstance(dset, h5py.Dataset) and dset.is_virtual:
            for source in dset.virtual_sources():
                names.setdefault(source.file_name, None)
    return list(names)


def check_index_sources(path: str | Path, h5: h5py.File | None = None, *, deep: bool = False) -> None:
    """Raise one-line :class:`InputError` unless every shard the index at ``path`` reads from exists, opens
    and carries the ``content_sha256`` the index recorded when it was built (``deep``: also recompute each
    shard's digest, reading all of it). Files without virtual datasets pass at once.

    For readers of HDF5 outputs (``vis``, ``extract``, :mod:`hybridgen.data`): call it right after opening a
    file (pass the open ``h5`` to avoid reopening); virtual datasets over missing shards would otherwise
    read fill values without any error.
    """
    from ..io.integrity import verify

    path = Path(path)
    own = h5 is None
    handle = h5py.File(path, "r") if own else h5
    try:
        sources = virtual_sources(handle)
        if not sources:
            return
        recorded = json.loads(_text(handle.attrs[SHARD_DIGESTS_ATTR])) if SHARD_DIGESTS_ATTR in handle.attrs else {}
    finally:
        if own:
            handle.close()
    missing, replaced = [], []
    for name in sources:
        source = path.parent / name
        if not source.is_file():
            missing.append(name)
            continue
        try:
            with h5py.File(source, "r") as shard:
                digest = _text(shard.attrs.get(DIGEST_ATTR, ""))
        except OSError:
            replaced.append(name)
            continue
        expected = recorded.get(name)
        if (expected is not None and digest != expected) or (deep and verify(source) is not None):
            replaced.append(name)
    if missing or replaced:
        parts = []
        if missing:
            parts.append(f"{len(missing)} missing ({_some(missing)})")
        if replaced:
            parts.append(f"{len(replaced)} unreadable or not the ones it was built over ({_some(replaced)})")
        raise InputError(f"'{path}' is an index over {len(sources)} shard file(s) beside it and "
                         f"{' and '.join(parts)}; copy the whole output folder (with shards/) or rerun the "
                         "config to complete it")


def _some(names: list[str], limit: int = 3) -> str:
    return ", ".join(names[:limit]) + (f" and {len(names) - limit} more" if len(names) > limit else "")
