"""What a file's bytes gave, remembered by the file's identity, so that one process reads an input file once.

A run reads some inputs several times: the run's fingerprint hashes every input file and scans each OBJ for
the MTL libraries it names, then the mesh cache needs the same hashes and the same scan for its key (a
10 MB OBJ: ~10 ms to hash, ~40 ms to scan). :class:`IdentityMemo` keeps such a derived value per file while
the file's identity - ``(device, inode, size, mtime_ns, ctime_ns)``, see :func:`file_identity` - is
unchanged. ``ctime`` changes on every write and cannot be set back by tools that restore ``mtime``
(``touch -d``, ``rsync -t``, ``cp -p``).

Racily clean files (as in git's index): a file changed within :data:`SETTLE_NS` of being read could change
again within the same timestamp tick and keep its identity, so what was read from it is used but not
remembered (:func:`is_settled`); neither is what was read from a file whose identity changed while it was
read. :mod:`hybridgen.run.input_hashes` applies the same rule to the hashes it keeps on disk.

Only the standard library is imported here, so io, run and physics can all use it.
"""
from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path
from typing import Callable, Generic, TypeVar

SETTLE_NS = 2_000_000_000
"""A file changed less than this long (ns) before it was read is not remembered (timestamp granularity of
common file systems is 1 ns to 2 s)."""

MAX_ENTRIES = 4096
"""Files remembered per memo; beyond it the oldest entries are forgotten."""

T = TypeVar("T")
Identity = tuple[int, int, int, int, int]


def file_identity(stat: os.stat_result) -> Identity:
    """``(device, inode, size, mtime_ns, ctime_ns)`` of a ``stat`` result."""
    return (stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns, stat.st_ctime_ns)


def is_settled(stat: os.stat_result, now_ns: int | None = None) -> bool:
    """True when the file's last change (``mtime`` or ``ctime``) lies more than :data:`SETTLE_NS` before
    ``now_ns`` (default: now), so that a later change must give it another identity."""
    now = time.time_ns() if now_ns is None else now_ns
    return now - max(stat.st_mtime_ns, stat.st_ctime_ns) > SETTLE_NS


def file_sha256(path: Path) -> str:
    """Hex SHA-256 of a file's bytes (read in full)."""
    with open(path, "rb") as handle:
        return hashlib.file_digest(handle, "sha256").hexdigest()


class IdentityMemo(Generic[T]):
    """``compute(path)`` per file, remembered in this process while the file's identity is unchanged and once
    the file has settled (see the module documentation). Values are shared between callers: keep them
    immutable (tuples, strings). ``computed`` / ``reused`` count this memo's calls."""

    def __init__(self, compute: Callable[[Path], T], max_entries: int = MAX_ENTRIES) -> None:
        self._compute = compute
        self._max_entries = max_entries
        self._values: dict[str, tuple[Identity, T]] = {}
        self.computed = 0
        self.reused = 0

    def __call__(self, path: Path) -> T:
        """The value for the file at ``path`` (OSError when it cannot be read, as ``compute`` raises)."""
        key = os.path.abspath(path)
        before = os.stat(key)
        known = self._values.get(key)
        if known is not None and known[0] == file_identity(before):
            self.reused += 1
            return known[1]
        value = self._compute(Path(path))
        self.computed += 1
        if is_settled(before) and file_identity(os.stat(key)) == file_identity(before):
            self._store(key, file_identity(before), value)
        return value

    def remember(self, path: Path, stat: os.stat_result, value: T) -> None:
        """Take ``value`` for the file at ``path`` as it was when ``stat`` was taken (e.g. a hash another cache
        holds for that identity); ignored when the file had not settled then."""
        if is_settled(stat):
            self._store(os.path.abspath(path), file_identity(stat), value)

    def clear(self) -> None:
        """Forget every remembered value."""
        self._values.clear()

    def _store(self, key: str, identity: Identity, value: T) -> None:
        self._values.pop(key, None)
        if len(self._values) >= self._max_entries:
            del self._values[next(iter(self._values))]  # the oldest entry (dicts keep insertion order)
        self._values[key] = (identity, value)


content_sha256: IdentityMemo[str] = IdentityMemo(file_sha256)
"""Hex SHA-256 of a file's bytes, read once per process and file identity (run fingerprints, mesh cache keys)."""
