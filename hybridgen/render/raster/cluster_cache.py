"""Triangle clusters of a mesh built once: shared by every raster view of a process and kept on disk.

:func:`~hybridgen.render.raster.triangle_clusters.build_clusters` costs ~0.24 s of CPU for a 1.4M-triangle mesh, paid
by every raster view at upload: by each of ``render_threads`` views of one run, and again by every run.
:func:`mesh_clusters` returns the same values (a build is deterministic) from

* a per-process memo of the last :data:`MEMO_ENTRIES` meshes, with one lock per mesh, so that raster threads
  uploading the same mesh at once build it once (the others wait for it);
* ``$HYBRIDGEN_CACHE_DIR/clusters`` (see :mod:`hybridgen.io.cache_folder`; ``off`` turns it off): one ``.npz``
  per mesh, written to a temporary name and renamed; a damaged or unreadable entry is a miss.

Both are keyed by content: SHA-256 over the vertex and face arrays (dtype, shape, bytes), the cluster size and
the source of :mod:`~hybridgen.render.raster.triangle_clusters` (~30 ms for 1.4M triangles), so an edited mesh or
cluster rule never meets a stale entry. The cached arrays are read-only.
"""
from __future__ import annotations

import dataclasses
import hashlib
import threading
import zipfile
from collections import OrderedDict
from functools import cache
from pathlib import Path

import numpy as np

from ...io.cache_folder import cache_path, write_entry
from . import triangle_clusters
from .triangle_clusters import MIN_TRIANGLES, TriangleClusters, build_clusters

MEMO_ENTRIES = 64
"""Meshes whose clusters a process keeps in memory (~0.6 KB per 1000 triangles: 0.9 MB for 1.4M)."""
_FIELDS = [field.name for field in dataclasses.fields(TriangleClusters)]

_memo: OrderedDict[str, TriangleClusters] = OrderedDict()
_locks: dict[str, threading.Lock] = {}
_guard = threading.Lock()


@cache
def _source_digest() -> bytes:
    """SHA-256 of the module that builds clusters (the code this process runs)."""
    return hashlib.sha256(Path(triangle_clusters.__file__ or "").read_bytes()).digest()


def content_key(vertices: np.ndarray, faces: np.ndarray) -> str:
    """The key of a mesh's clusters: its arrays' dtype, shape and bytes, and the cluster code."""
    digest = hashlib.sha256(_source_digest())
    for array in (np.ascontiguousarray(vertices), np.ascontiguousarray(faces)):
        digest.update(f"\0{array.dtype.str}{array.shape}\0".encode())
        digest.update(memoryview(array).cast("B"))
    return digest.hexdigest()


def mesh_clusters(vertices: np.ndarray, faces: np.ndarray) -> TriangleClusters | None:
    """:func:`~hybridgen.render.raster.triangle_clusters.build_clusters` of ``vertices`` (N, 3) and ``faces`` (M, 3),
    from the memo or the disk cache when this mesh was built before (same values)."""
    if len(faces) < MIN_TRIANGLES:
        return None
    key = content_key(vertices, faces)
    with _guard:
        lock = _locks.setdefault(key, threading.Lock())
    with lock:  # a second thread with the same mesh waits for the first one's build
        with _guard:
            found = _memo.get(key)
            if found is not None:
                _memo.move_to_end(key)
                return found
        folder = cache_path("clusters")
        entry = folder / f"{key}.npz" if folder is not None else None
        clusters = _read(entry) if entry is not None else None
        if clusters is None:
            clusters = build_clusters(vertices, faces)
            assert clusters is not None
            if entry is not None:
                _write(entry, clusters)
        for name in _FIELDS:
            getattr(clusters, name).setflags(write=False)
        with _guard:
            _memo[key] = clusters
            while len(_memo) > MEMO_ENTRIES:
                _locks.pop(_memo.popitem(last=False)[0], None)
    return clusters


def clear_memo() -> None:
    """Forget the clusters kept in memory (the disk cache stays)."""
    with _guard:
        _memo.clear()


def _read(entry: Path) -> TriangleClusters | None:
    try:
        with np.load(entry, allow_pickle=False) as data:
            arrays = {name: data[name] for name in _FIELDS}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    sizes = {len(array) for array in arrays.values()}
    return TriangleClusters(**arrays) if len(sizes) == 1 else None


def _write(entry: Path, clusters: TriangleClusters) -> None:
    """Store ``clusters`` under ``entry`` atomically; a cache that cannot be written is silently skipped."""
    write_entry(entry, lambda out: np.savez(out, **{name: getattr(clusters, name) for name in _FIELDS}))
