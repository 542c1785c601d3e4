"""A disk cache of parsed mesh files, so that a run's time to first keypoint is not spent re-parsing.

:func:`load_objects_cached` is the Python API's ``hg.load_objects``: it returns what
:func:`hybridgen.io.mesh_loader.load_objects` returns (the same objects, errors and notices), but keeps
the parsed objects (in the file's own frame, with the properties the label pass needs - face normals and
whether each part is a closed volume - already computed) under ``$HYBRIDGEN_CACHE_DIR/meshes`` (default
``$XDG_CACHE_HOME/hybridgen/meshes`` or ``~/.cache/hybridgen/meshes``, see :mod:`hybridgen.io.cache_folder`).
The key is a SHA-256 over the bytes of the file and of every MTL / texture file it names, the options that
change parsing (``name``, ``up_axis``), the hybridgen version and the source of the modules that build the
objects - so an edited file, texture or loader never meets a stale entry. The file hashes and the scan for
the names come from :mod:`hybridgen.io.file_identity`'s per-process memos, which the run's fingerprint has
usually filled already: a warm load reads only the entry, and imports neither trimesh nor SciPy (about 0.6 s
of a process's start; nothing in an entry is a trimesh object). Entries are written to a temporary name and
renamed (atomic); a damaged or unreadable entry is a miss. ``HYBRIDGEN_CACHE_DIR=off`` (or an unwritable
folder) turns the cache off. A file whose MTL or textures are missing is never cached: it is the loader's
error (or, with ``--lenient``, its notice) every time.

Entries are pickles: the cache folder must be writable only by its user (as any ``~/.cache``).
"""
from __future__ import annotations

import hashlib
import os
import pickle
from functools import cache
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .._version import __version__
from ..config.notices import notice, recording_notices
from .cache_folder import cache_path, write_entry
from .file_identity import content_sha256
from .mesh_references import check_references, referenced_files

_FORMAT = 3
"""Bumped when what an entry holds changes (2: notices of missing MTL/texture files are never stored)."""


def cache_dir() -> Path | None:
    """The folder of cached meshes (``meshes`` in hybridgen's cache folder), or None when turned off."""
    return cache_path("meshes")


@cache
def _source_digest() -> str:
    """SHA-256 of the modules whose code decides what a loaded object holds (read once: it is the code this
    process runs)."""
    from ..scene import material, mesh_object
    from . import mesh_loader

    digest = hashlib.sha256()
    for module in (mesh_loader, mesh_object, material):
        digest.update(Path(module.__file__ or "").read_bytes())
    return digest.hexdigest()


def cache_key(path: Path, options: dict[str, Any]) -> str:
    """The entry name of ``path`` parsed with ``options`` (content, not file times, decides)."""
    digest = hashlib.sha256(f"{_FORMAT}\0{__version__}\0{_source_digest()}\0{sorted(options.items())!r}".encode())
    files, queue = [], [path]
    while queue:  # the OBJ, the MTL libraries it names, the textures those name
        file = queue.pop(0)
        if file in files:
            continue
        files.append(file)
        try:
            queue += referenced_files(file)
        except OSError:
            pass
    for file in files:
        digest.update(b"\0" + os.fsencode(file.name) + b"\0")
        try:
            digest.update(bytes.fromhex(content_sha256(file)))
        except OSError:
            digest.update(b"<missing>")
    return digest.hexdigest()


def load_objects_cached(path: str | Path, *, name: str | None = None, category_id: int | None = None,
                        local2world: np.ndarray | None = None, up_axis: str = "auto",
                        attributes: dict[str, Any] | None = None,
                        notify: Callable[[str], None] | None = None) -> list[Any]:
    """Read a mesh file into one :class:`~hybridgen.scene.mesh_object.MeshObject` per object (per material of
    it), as :func:`hybridgen.io.mesh_loader.load_objects` does - same arguments, same objects, errors and
    notices - through the disk cache of parsed meshes (module docstring): a file parsed once (by any path,
    pose, category or attributes) is read back from its entry.

    ``local2world`` (metres) poses every object; ``name``, ``up_axis`` and the object naming are the
    loader's. ``notify`` receives one line for what Blender would do differently (an object with several
    materials), on a hit as on a miss."""
    from .mesh_loader import load_objects

    folder = cache_dir()
    file = Path(path)
    base = None if local2world is None else np.asarray(local2world, dtype=np.float64)
    if (folder is None or not file.is_file()  # a missing file: the loader's own error
            or (base is not None and not np.all(np.isfinite(base)))  # the loader's own error
            or (file.suffix.lower() == ".obj" and check_references(file) is not None)):  # its error or notice
        return load_objects(path, name=name, category_id=category_id, local2world=local2world, up_axis=up_axis,
                            attributes=attributes, notify=notify)
    base = np.eye(4) if base is None else base
    entry = folder / f"{cache_key(file, {'name': name, 'up_axis': str(up_axis)})}.pickle"
    cached = _read(entry)
    hit = cached is not None
    if cached is None:
        notices: list[str] = []
        with recording_notices() as issued:  # e.g. repaired vertex normals: given again on every hit
            objects = load_objects(file, name=name, up_axis=up_axis, notify=notices.append)
        if not all(_exact_under_any_pose(obj.local2world) for obj in objects):  # e.g. glTF node transforms
            for line in notices:
                if notify is not None:
                    notify(line)
            return load_objects(path, name=name, category_id=category_id, local2world=local2world,
                                up_axis=up_axis, attributes=attributes)
        for obj in objects:  # what the label pass asks of every object, computed once
            _ = obj.face_normals, obj.is_closed
        cached = {"objects": objects, "notices": notices, "issued": issued}
        _write(entry, cached)
    for line in cached["notices"]:
        if notify is not None:
            notify(line)
    for issued_notice in cached["issued"] if hit else ():  # a miss has issued them already
        notice(**issued_notice)
    objects = cached["objects"]
    for obj in objects:
        obj.local2world = base @ obj.local2world  # exact: a signed permutation (see _exact_under_any_pose)
        obj.category_id = category_id
        if "source_path" in obj.attributes:  # the entry is keyed by content: it may come from another path
            obj.attributes["source_path"] = str(file)
        obj.attributes.update(attributes or {})
    return objects


def _exact_under_any_pose(matrix: np.ndarray) -> bool:
    """Whether ``pose @ matrix`` is bit-identical to what the loader computes for any ``pose``: the file's
    own part transform is an axis turn (a signed permutation, no translation), so every product is exact
    and a cached run writes the same bytes as an uncached one."""
    rotation = matrix[:3, :3]
    return bool(np.all(np.isin(rotation, (-1.0, 0.0, 1.0))) and np.all(np.abs(rotation).sum(axis=0) == 1)
                and np.all(np.abs(rotation).sum(axis=1) == 1) and not np.any(matrix[:3, 3])
                and np.array_equal(matrix[3], [0.0, 0.0, 0.0, 1.0]))


def _read(entry: Path) -> dict[str, Any] | None:
    try:
        with open(entry, "rb") as handle:
            value = pickle.load(handle)
    except (OSError, EOFError, pickle.UnpicklingError, AttributeError, ImportError, TypeError, ValueError):
        return None
    return value if isinstance(value, dict) and "objects" in value and "issued" in value else None


def _write(entry: Path, value: dict[str, Any]) -> None:
    """Store ``value`` under ``entry`` atomically; a cache that cannot be written is silently skipped."""
    write_entry(entry, lambda out: pickle.dump(value, out, protocol=pickle.HIGHEST_PROTOCOL))
