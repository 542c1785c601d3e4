"""SHA-256 of input files, remembered by file identity so that a rerun does not read every input again.

A run's fingerprint (:mod:`hybridgen.run.fingerprint`) holds the content hash of every file the config
names - up to 10,000 files per named folder (texture libraries, model folders). Hashing them on every run
(and on every resume) reads all their bytes. :class:`InputHashes` keeps each hash with the file's identity
``(device, inode, size, mtime_ns, ctime_ns)`` in ``input_hashes.json`` in hybridgen's cache folder
(:mod:`hybridgen.io.cache_folder`; ``HYBRIDGEN_CACHE_DIR=off`` turns it off), shared by every output folder
that uses the same assets. A file whose identity changed in any field is hashed again; ``ctime`` changes on
every write and cannot be set back by tools that restore ``mtime`` (``touch -d``, ``rsync -t``, ``cp -p``).

As with git's index, a file changed within :data:`~hybridgen.io.file_identity.SETTLE_NS` of being hashed
could change again within the same timestamp tick, so its hash is used but not remembered; a file that
changes while it is hashed is not remembered either (the rule of :mod:`hybridgen.io.file_identity`, whose
per-process memo also receives every hash used here, so the mesh cache's key does not read the file again).
The cache is written to a temporary name and renamed (concurrent runs: the last writer
wins, a lost entry is only hashed again), merged with what another run stored meanwhile, and bounded to
:data:`MAX_ENTRIES` entries (least recently used dropped). A damaged or unreadable cache is ignored.
"""
from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path
from typing import Any

from ..io.cache_folder import cache_path
from ..io.file_identity import content_sha256, file_identity, file_sha256, is_settled

CACHE_FILE = "input_hashes.json"
MAX_ENTRIES = 100_000
_FORMAT = 1
_USE_RESOLUTION_S = 86_400  # last-use times are refreshed at most daily (a hit rarely rewrites the cache)


def default_cache_file() -> Path | None:
    """``input_hashes.json`` in hybridgen's cache folder, or None when ``HYBRIDGEN_CACHE_DIR=off``."""
    return cache_path(CACHE_FILE)


def _identity(stat: os.stat_result) -> list[int]:
    return list(file_identity(stat))


def _read_entries(path: Path | None) -> dict[str, list[Any]]:
    if path is None:
        return {}
    try:
        with open(path, "rb") as handle:
            data = json.loads(handle.read(64 << 20))  # a cache of MAX_ENTRIES is ~20 MB
    except (OSError, ValueError):
        return {}
    if not isinstance(data, dict) or data.get("format") != _FORMAT or not isinstance(data.get("files"), dict):
        return {}
    return {key: value for key, value in data["files"].items()
            if isinstance(value, list) and len(value) == 7 and isinstance(value[5], str)}


class InputHashes:
    """Content hashes of input files, cached in ``cache_file`` (None: no cache, every file is hashed).
    :meth:`save` stores what was hashed; ``hashed`` / ``reused`` count files of this object's lookups."""

    def __init__(self, cache_file: Path | None) -> None:
        self.cache_file = cache_file
        self._entries = _read_entries(cache_file)  # absolute path -> identity (5 ints), sha256, last use (s)
        self._changed = False
        self.hashed = 0
        self.reused = 0

    @classmethod
    def default(cls) -> "InputHashes":
        """The cache in hybridgen's cache folder (see the module documentation)."""
        return cls(default_cache_file())

    def sha256(self, path: Path) -> str:
        """The hex SHA-256 of the file at ``path`` (from the cache when its identity is unchanged)."""
        key = os.path.abspath(path)  # two names of one file: two entries, each checked by its identity
        before = os.stat(key)
        identity = _identity(before)
        entry = self._entries.get(key)
        now = time.time()
        if entry is not None and entry[:5] == identity:
            self.reused += 1
            if now - entry[6] > _USE_RESOLUTION_S:
                entry[6] = int(now)
                self._changed = True
            content_sha256.remember(Path(key), before, str(entry[5]))
            return str(entry[5])
        digest = file_sha256(Path(key))
        self.hashed += 1
        if is_settled(before) and _identity(os.stat(key)) == identity:
            self._entries[key] = [*identity, digest, int(now)]
            self._changed = True
            content_sha256.remember(Path(key), before, digest)
        return digest

    def save(self) -> None:
        """Store the cache (merged with entries another run stored meanwhile) if anything changed; a cache
        folder that cannot be written is skipped silently (the cache is an optimisation)."""
        if self.cache_file is None or not self._changed:
            return
        merged = {**_read_entries(self.cache_file), **self._entries}
        if len(merged) > MAX_ENTRIES:
            newest = sorted(merged.items(), key=lambda item: item[1][6], reverse=True)[:MAX_ENTRIES]
            merged = dict(newest)
        try:
            self.cache_file.parent.mkdir(parents=True, exist_ok=True)
            fd, temp = tempfile.mkstemp(prefix=f".{CACHE_FILE}.", suffix=".incomplete", dir=self.cache_file.parent)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as handle:
                    json.dump({"format": _FORMAT, "files": merged}, handle, separators=(",", ":"))
                os.replace(temp, self.cache_file)
            except BaseException:
                os.unlink(temp)
                raise
        except OSError:
            return
        self._entries = merged
        self._changed = False
