"""Self-checking HDF5 outputs: a SHA-256 over every dataset's stored bytes and the file's attributes.

:func:`seal` stores the digest as the ``content_sha256`` attribute just before a file is committed;
:func:`verify` recomputes it. The digest covers each dataset's name, dtype, shape and stored bytes - the
*compressed* chunks as they lie on disk for chunked datasets (read with ``read_direct_chunk``, nothing is
decompressed, so checking costs one read of the file), the values for contiguous ones - each dataset's
attributes (they say how a pass is encoded) and every file attribute except the digest itself. A flipped
bit in any chunk, a truncated file or a changed attribute fails the check; a damaged file header fails to open. Virtual datasets are skipped (an index checks its
sources with :func:`hybridgen.run.shard_index.check_index_sources`).

Two schemes, named by the file attribute ``content_sha256_scheme`` (absent: the first):

- the chunks of every chunked dataset are hashed inline, in chunk order;
- ``chunk-streams``: each chunked dataset contributes the SHA-256 of its chunk stream (the same bytes the
  first scheme hashes inline) instead. A writer that stores chunks in order hashes them as it writes them
  (:class:`ChunkStream`), so sealing a finished file reads no chunk back (the single-file HDF5 writer: a
  full read of the file at the end of every run before). Checking costs the same under both.
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import h5py
import numpy as np

DIGEST_ATTR = "content_sha256"
SCHEME_ATTR = "content_sha256_scheme"
CHUNK_STREAMS = "chunk-streams"


class ChunkStream:
    """The SHA-256 of one dataset's chunk stream, fed while the chunks are written: ``add`` each chunk as it
    lies on disk (offset tuple, filter mask, stored bytes) in increasing offset order. ``hexdigest`` is None
    when the chunks did not arrive in that order (then the seal reads them back)."""

    def __init__(self) -> None:
        self._hash = hashlib.sha256()
        self._last: tuple[int, ...] | None = None
        self._in_order = True

    def add(self, offset: tuple[int, ...], mask: int, data: Any) -> None:
        view = memoryview(data).cast("B")
        if self._last is not None and offset <= self._last:
            self._in_order = False
        self._last = offset
        self._hash.update(f"{offset}:{mask}:{view.nbytes}".encode())
        self._hash.update(view)

    def hexdigest(self) -> str | None:
        return self._hash.hexdigest() if self._in_order else None


def _update_value(digest: "hashlib._Hash", value: Any) -> None:
    array = np.asarray(value)
    if array.dtype.kind == "O":
        digest.update(repr([v.decode("utf-8", "replace") if isinstance(v, bytes) else v
                            for v in array.ravel().tolist()]).encode())
    else:
        digest.update(str(array.dtype).encode() + str(array.shape).encode())
        digest.update(np.ascontiguousarray(array).tobytes())


def _update_attributes(digest: "hashlib._Hash", attrs: h5py.AttributeManager, prefix: str) -> None:
    for key in sorted(attrs):
        if key != DIGEST_ATTR:
            digest.update(f"\0{prefix}@{key}\0".encode())
            _update_value(digest, attrs[key])


def _update_chunks(digest: "hashlib._Hash", dset: h5py.Dataset) -> None:
    """Every stored chunk of ``dset`` in offset order: ``offset:mask:length`` and its bytes."""
    dsid = dset.id
    infos: list[Any] = []
    if hasattr(dsid, "chunk_iter"):  # HDF5 >= 1.12.3: one pass over the chunk index (20x faster)
        dsid.chunk_iter(infos.append)
    else:
        infos = [dsid.get_chunk_info(i) for i in range(dsid.get_num_chunks())]
    for info in sorted(infos, key=lambda item: item.chunk_offset):
        mask, data = dsid.read_direct_chunk(info.chunk_offset)
        digest.update(f"{info.chunk_offset}:{mask}:{len(data)}".encode())
        digest.update(data)


def _update_dataset(digest: "hashlib._Hash", name: str, dset: h5py.Dataset, streams: bool,
                    known: dict[str, str]) -> None:
    digest.update(f"\0{name}\0{dset.dtype}\0{dset.shape}\0".encode())
    _update_attributes(digest, dset.attrs, name)
    if dset.chunks is None:
        _update_value(digest, dset[()])
    elif not streams:
        _update_chunks(digest, dset)
    else:
        stream = known.get(name)
        if stream is None:
            chunks = hashlib.sha256()
            _update_chunks(chunks, dset)
            stream = chunks.hexdigest()
        digest.update(stream.encode())


def content_digest(h5: h5py.File, streams: dict[str, ChunkStream] | None = None) -> str:
    """The hex SHA-256 of ``h5``'s datasets (stored bytes) and attributes, ``content_sha256`` excluded, under
    the file's scheme (``content_sha256_scheme``). ``streams``: chunk streams hashed while writing, by dataset
    name (used by the ``chunk-streams`` scheme; a dataset without one, or fed out of order, is read).
    Datasets are opened one at a time: an open virtual dataset holds its whole source mapping (~5 KB per
    source file in HDF5), so holding all of an index's datasets at once grew with the number of shards."""
    scheme = h5.attrs.get(SCHEME_ATTR)
    by_streams = (scheme.decode() if isinstance(scheme, bytes) else scheme) == CHUNK_STREAMS
    known = {name: value for name, stream in (streams or {}).items()
             if (value := stream.hexdigest()) is not None}
    digest = hashlib.sha256()
    names: list[str] = []
    h5.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
    for name in sorted(names):
        dset = h5[name]
        if not dset.is_virtual:
            _update_dataset(digest, name, dset, by_streams, known)
        del dset
    _update_attributes(digest, h5.attrs, "")
    return digest.hexdigest()


def seal(h5: h5py.File, streams: dict[str, ChunkStream] | None = None) -> str:
    """Store the digest of ``h5`` (open for writing, complete) as its ``content_sha256`` attribute. With
    ``streams`` (the chunk streams of its chunked datasets, hashed while writing; see :class:`ChunkStream`)
    the file is sealed under the ``chunk-streams`` scheme, reading back only what no stream covers."""
    if streams is not None:
        h5.attrs[SCHEME_ATTR] = CHUNK_STREAMS
    h5.flush()
    value = content_digest(h5, streams)
    h5.attrs[DIGEST_ATTR] = value
    return value


def verify(path: str | Path) -> str | None:
    """Why the file at ``path`` cannot be trusted (unreadable, unsealed, digest differs), or None if it is
    intact."""
    try:
        with h5py.File(path, "r") as h5:
            stored = h5.attrs.get(DIGEST_ATTR)
            if stored is None:
                return "carries no content_sha256 (not sealed)"
            actual = content_digest(h5)
    except (OSError, RuntimeError, ValueError, KeyError) as exc:
        return f"unreadable ({str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__})"
    stored = stored.decode() if isinstance(stored, bytes) else str(stored)
    return None if stored == actual else "content does not match its content_sha256 (damaged)"
