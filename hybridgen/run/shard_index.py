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

from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..io.atomic import commit, temporary_path

SCENE_RECORDS = ("object_states", "light_states")
UNIT_ATTRIBUTES = ("scene_index", "chunk_index", "scene_keypoints")


def _virtual(h5: h5py.File, key: str, pieces: list[tuple[str, int, int, tuple[int, ...]]], dtype: Any,
             tail: tuple[int, ...]) -> None:
    """Create ``key`` mapping ``(relative file, offset, count, source shape)`` pieces, without timestamps."""
    total = sum(count for _, _, count, _ in pieces)
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_obj_track_times(False)
    for filename, offset, count, source_shape in pieces:
        target = h5py.h5s.create_simple((total, *tail))
        target.select_hyperslab((offset,) + (0,) * len(tail), (count, *tail))
        source = h5py.h5s.create_simple(source_shape)
        source.select_all()
        dcpl.set_virtual(target, filename.encode(), key.encode(), source)
    h5py.h5d.create(h5.id, key.encode(), h5py.h5t.py_create(dtype), h5py.h5s.create_simple((total, *tail)),
                    dcpl=dcpl)


def build_index(path: Path, shards: list[Path]) -> Path:
    """Write ``path`` over ``shards`` (already in scene, chunk order); returns ``path``."""
    opened = [h5py.File(shard, "r") for shard in shards]
    try:
        counts = [len(f["keypoint_index"]) for f in opened]
        per_keypoint = [k for k in opened[0] if isinstance(opened[0][k], h5py.Dataset)
                        and opened[0][k].shape[:1] == (counts[0],) and k not in SCENE_RECORDS]
        temp = temporary_path(path)
        with h5py.File(temp, "w", libver="v110") as index:
            offsets = np.concatenate([[0], np.cumsum(counts)])
            for key in per_keypoint:
                first = opened[0][key]
                if h5py.check_string_dtype(first.dtype) is not None:
                    values = np.concatenate([f[key][()] for f in opened])
                    index.create_dataset(key, data=values, dtype=first.dtype, track_times=False)
                    continue
                pieces = [(str(Path(shard).relative_to(path.parent)), int(offsets[i]), counts[i], f[key].shape)
                          for i, (shard, f) in enumerate(zip(shards, opened))]
                _virtual(index, key, pieces, first.dtype, first.shape[1:])
            scenes = np.concatenate([[f.attrs["scene_index"]] * c for f, c in zip(opened, counts)]).astype(np.int64)
            index.create_dataset("scene_index", data=scenes, track_times=False)
            first_chunks = {}
            for f in opened:
                first_chunks.setdefault(int(f.attrs["scene_index"]), f)
            for key in SCENE_RECORDS:
                if key in opened[0]:
                    values = [first_chunks[s][key][()] for s in sorted(first_chunks)]
                    index.create_dataset(key, data=values, dtype=h5py.string_dtype(), track_times=False)
            for key, value in opened[0].attrs.items():
                if key not in UNIT_ATTRIBUTES:
                    index.attrs[key] = value
            index.attrs["number_of_scenes"] = len(first_chunks)
            index.attrs["layout"] = "sharded: virtual datasets over shards/*.hdf5"
    finally:
        for f in opened:
            f.close()
    commit(temp, path)
    return path
