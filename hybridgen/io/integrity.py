"""Self-checking HDF5 outputs: a SHA-256 over every dataset's stored bytes and the file's attributes.

:func:`seal` stores the digest as the ``content_sha256`` attribute just before a file is committed;
:func:`verify` recomputes it. The digest covers each dataset's name, dtype, shape and stored bytes - the
*compressed* chunks as they lie on disk for chunked datasets (read with ``read_direct_chunk``, nothing is
decompressed, so checking costs one read of the file), the values for contiguous ones - each dataset's
attributes (they say how a pass is encoded) and every file attribute except the digest itself. A flipped
bit in any chunk, a truncated file or a changed attribute fails the check; a damaged file header fails to open. Virtual datasets are skipped (an index checks its
sources with :func:`hybridgen.run.shard_index.check_index_sources`).
"""
from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import h5py
import numpy as np

DIGEST_ATTR = "content_sha256"


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


def _update_dataset(digest: "hashlib._Hash", name: str, dset: h5py.Dataset) -> None:
    digest.update(f"\0{name}\0{dset.dtype}\0{dset.shape}\0".encode())
    _update_attributes(digest, dset.attrs, name)
    if dset.chunks is None:
        _update_value(digest, dset[()])
        return
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


def content_digest(h5: h5py.File) -> str:
    """The hex SHA-256 of ``h5``'s datasets (stored bytes) and attributes, ``content_sha256`` excluded.
    Datasets are opened one at a time: an open virtual dataset holds its whole source mapping (~5 KB per
    source file in HDF5), so holding all of an index's datasets at once grew with the number of shards."""
    digest = hashlib.sha256()
    names: list[str] = []
    h5.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
    for name in sorted(names):
        dset = h5[name]
        if not dset.is_virtual:
            _update_dataset(digest, name, dset)
        del dset
    _update_attributes(digest, h5.attrs, "")
    return digest.hexdigest()


def seal(h5: h5py.File) -> str:
    """Store the digest of ``h5`` (open for writing, complete) as its ``content_sha256`` attribute."""
    h5.flush()
    value = content_digest(h5)
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
