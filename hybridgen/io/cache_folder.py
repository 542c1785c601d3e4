"""hybridgen's cache folder: where derived data that is expensive to recompute is kept between runs.

``$HYBRIDGEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/hybridgen``, else ``~/.cache/hybridgen``. Parsed meshes
(:mod:`hybridgen.io.mesh_cache`), input-file hashes (:mod:`hybridgen.run.input_hashes`), convex
decompositions (:mod:`hybridgen.physics.shapes`) and the raster view's triangle clusters
(:mod:`hybridgen.render.raster.cluster_cache`) live in it. ``HYBRIDGEN_CACHE_DIR=off`` (or ``0``, ``none``)
turns all four off. Nothing here imports more than the standard library, so every
layer (io, run, physics) can use it.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import BinaryIO, Callable

CACHE_ENV = "HYBRIDGEN_CACHE_DIR"
OFF_VALUES = ("off", "0", "none")


def cache_root() -> Path:
    """The cache folder (see the module documentation); it may not exist yet."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "hybridgen"


def cache_path(name: str) -> Path | None:
    """``name`` (a file or folder) in the cache folder, or None when ``$HYBRIDGEN_CACHE_DIR`` turns caching off."""
    if os.environ.get(CACHE_ENV, "").lower() in OFF_VALUES:
        return None
    return cache_root() / name


def write_entry(entry: Path, write: Callable[[BinaryIO], None]) -> None:
    """Store a cache entry: ``write`` fills a new private temporary file beside ``entry``, which is then renamed
    to it (atomic: a reader sees the old entry or the whole new one). A cache that cannot be written is
    silently skipped (the caller computed the value anyway)."""
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        handle, temp = tempfile.mkstemp(dir=entry.parent, prefix=f".{entry.name}.", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as out:
                write(out)
            os.replace(temp, entry)
        except BaseException:
            Path(temp).unlink(missing_ok=True)
            raise
    except OSError:
        pass
