"""Resumable non-sharded runs: keypoint chunks rendered as verified part files, merged into one ordinary file.

A run of a config whose only writer is ``writer.Hdf5Writer`` (``layout: single``, one scene, no
``keypoints_per_chunk``) renders its keypoints in parts of ``resume_chunk_keypoints`` into the hidden folder
``<output_dir>/.<file_name>.parts/``: each part is a work unit of the sharded machinery
(:mod:`hybridgen.run.runner`) - fingerprinted, sealed, renamed into place only when complete - so a killed
run, rerun, reuses every part that verifies and renders only the rest. The parts share one scene, built
once per process (:mod:`hybridgen.run.scene_reuse`). The default (``-1``, :func:`part_keypoints`) stages
every such run: parts of :data:`DEFAULT_CHUNK_KEYPOINTS` when the config path-traces, of
:data:`DEFAULT_LABEL_CHUNK_KEYPOINTS` when it only rasterizes labels (fewer, larger parts: each part uploads
the scene to the rasterizer again). Merging is a raw copy in this thread, so staging costs what hashing the
parts, copying their chunks once and deleting them cost (``tools/bench_reliability.py``: ~10 % of a
400-keypoint 128x96 label run, nothing measurable beside path tracing).

Each part records a *journal* (:data:`JOURNAL_ATTR`): the writer's options and the order of the calls the
writer received (datasets, records and attributes of each renderer, then the scene records and run
attributes). :func:`consolidate` replays those calls through the same
:class:`~hybridgen.io.hdf5_single.Hdf5SingleFileWriter` over all keypoints, with each chunk's stored
(compressed) bytes copied verbatim from its part (``read_direct_chunk`` / ``write_direct_chunk``: nothing
is decompressed or encoded again). The result is the file an uninterrupted direct run writes, byte for
byte, whether or not the run was interrupted; the staging folder is removed afterwards.

A run whose keypoints fit in one part (the default for label runs of up to
:data:`DEFAULT_LABEL_CHUNK_KEYPOINTS` keypoints) has nothing to merge: its only part is a *whole* unit
(:mod:`hybridgen.run.scene_reuse`) that writes the direct run's file under a name of its own in the staging
folder, and the runner renames it into place. A killed attempt leaves at most a temporary file there; it is
rendered again from the start, as before (a part that is never complete is never resumed).
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
from dataclasses import asdict
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..errors import InputError
from ..io.frame_sink import PassLayout
from ..io.hdf5_single import Hdf5Options, Hdf5SingleFileWriter

JOURNAL_ATTR = "staged_journal"
UNIT_ATTRIBUTES = ("scene_index", "chunk_index", "scene_keypoints")
DEFAULT_CHUNK_KEYPOINTS = 50  # keypoints per part of a run that path-traces (seconds per keypoint)
DEFAULT_LABEL_CHUNK_KEYPOINTS = 200  # keypoints per part of a label-only run (milliseconds per keypoint)


def part_keypoints(requested: int, path_traces: bool) -> int:
    """Keypoints per part of a non-sharded single-file run: ``requested`` (``resume_chunk_keypoints``) when
    it is >= 0 (0: write the file directly, a killed run starts over), else the default for the run's kind."""
    if requested >= 0:
        return requested
    return DEFAULT_CHUNK_KEYPOINTS if path_traces else DEFAULT_LABEL_CHUNK_KEYPOINTS


def canonical(value: Any) -> str:
    """An attribute value as text that is the same before it is stored and after h5py reads it back."""
    return repr(np.asarray(value).tolist())


def staging_folder_name(file_name: str, limit: int = 255) -> str:
    """The hidden folder (inside ``output_dir``) holding the parts of ``file_name``: ``.<file_name>.parts``, or
    for a name too long for that on a filesystem allowing ``limit`` bytes per name (a legal ``file_name`` of
    up to ``limit`` bytes), ``.<file_name cut>~<12 hex of its SHA-256>.parts`` - the same folder on every
    rerun, so a killed run still resumes."""
    name = f".{file_name}.parts"
    if len(os.fsencode(name)) <= limit:
        return name
    tag = "~" + hashlib.sha256(os.fsencode(file_name)).hexdigest()[:12]
    room = max(0, limit - len(f"{tag}.parts") - 1)
    cut = os.fsencode(file_name)[:room].decode("utf-8", "ignore")  # whole characters of a UTF-8 name
    while len(os.fsencode(f".{cut}{tag}.parts")) > limit:  # surrogate escapes of a non-UTF-8 name
        cut = cut[:-1]
    return f".{cut}{tag}.parts"


class JournalingWriter(Hdf5SingleFileWriter):
    """An :class:`Hdf5SingleFileWriter` for one part that also stores how it was called (the journal)."""

    def __init__(self, path: str | Path, options: Hdf5Options | None = None, **given: Any) -> None:
        super().__init__(path, options, **given)
        self._journal: dict[str, Any] = {"compression": self.compression, "compression_level": self.level,
                                         "encoding": self.encoding, "begins": []}

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        self._journal["begins"].append({
            "layouts": [asdict(layout) for layout in layouts],
            "records": list(camera_records),
            "attributes": {key: canonical(value) for key, value in attributes.items()}})
        super().begin(n_keypoints, layouts, camera_records, attributes)

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        self._journal["records"] = list(records or {})
        self._journal["attributes"] = [key for key in (attributes or {}) if key not in UNIT_ATTRIBUTES]
        return super().finalize(records, {**(attributes or {}), JOURNAL_ATTR: json.dumps(self._journal)})


class _ReplayWriter(Hdf5SingleFileWriter):
    """Stores chunks that are already encoded and compressed (copied from parts) in keypoint order."""

    def write_stored(self, index: int, jobs: dict[str, Any]) -> None:
        """Store keypoint ``index`` now, in this thread: per key the stored chunk bytes (None: no chunk) or a
        JSON value - the calls the writer thread makes for a direct write, in the same order (no encoding,
        no compression, no hand-over between threads: a raw copy)."""
        assert self._file is not None, "write_stored() before begin()"
        self._store(self._file, index, jobs)


def _layout(entry: dict[str, Any]) -> PassLayout:
    value_range = entry["value_range"]
    return PassLayout(**{**entry, "shape": tuple(entry["shape"]),
                         "value_range": tuple(value_range) if value_range is not None else None})


class _StoredChunks:
    """Reads one dataset's stored (compressed) chunks of a part as they lie on disk."""

    def __init__(self, dset: h5py.Dataset) -> None:
        self.dset = dset
        self.dsid = dset.id
        self.tail = (0,) * (dset.ndim - 1)
        self.derived = self.dsid.get_num_chunks() == 0  # a pass derived on read: no chunk is ever written

    def __getitem__(self, local: int) -> bytes | None:
        if self.derived:
            return None
        try:
            mask, data = self.dsid.read_direct_chunk((local, *self.tail))
        except (KeyError, RuntimeError, OSError):
            raise InputError(f"'{self.dset.file.filename}': chunk {local} of '{self.dset.name}' is missing; "
                             "rerun with --restart") from None
        if mask != 0:
            raise InputError(f"'{self.dset.file.filename}': chunk {local} of '{self.dset.name}' has filter mask "
                             f"{mask}")
        return data


def _read_journal(part: h5py.File) -> dict[str, Any]:
    text = part.attrs.get(JOURNAL_ATTR)
    if text is None:
        raise InputError(f"'{part.filename}' is not a part of a resumable run (no {JOURNAL_ATTR})")
    return json.loads(text.decode() if isinstance(text, bytes) else str(text))


def _text_value(value: Any) -> Any:
    return json.loads(value.decode() if isinstance(value, bytes) else str(value))


def _read_all(parts: list[Path], key: str) -> np.ndarray:
    arrays = []
    for path in parts:
        with h5py.File(path, "r") as part:
            arrays.append(part[key][()])
    return np.concatenate(arrays)


def _replay_keypoints(writer: _ReplayWriter, part: h5py.File, first: int, layouts: list[PassLayout]) -> int:
    """Store every keypoint of ``part`` (stored chunks, JSON values) as keypoints ``first...``; their count."""
    sources: list[tuple[str, Any]] = [
        (layout.key, [_text_value(v) for v in part[layout.key][()]] if layout.dtype == "json"
         else _StoredChunks(part[layout.key])) for layout in layouts]
    count = len(part["keypoint_index"])
    for local in range(count):
        writer.write_stored(first + local, {key: source[local] for key, source in sources})
    return count


def consolidate(target: Path, parts: list[Path]) -> Path:
    """Merge ``parts`` (one scene's chunks in keypoint order, verified) into ``target`` by replaying their
    journal; returns ``target``. One part is open at a time; the file is written under a temporary name and
    renamed when complete."""
    keypoints = _read_all(parts, "keypoint_index")
    if not np.array_equal(keypoints, np.arange(len(keypoints))):
        raise InputError(f"the parts in '{parts[0].parent}' do not cover the keypoints in order; "
                         "rerun with --restart")
    with h5py.File(parts[0], "r") as first_part:
        journal = _read_journal(first_part)
        run_attributes = dict(first_part.attrs)
        scene_records = {key: _text_value(first_part[key][()]) for key in journal["records"]}
    writer = _ReplayWriter(target, compression=journal["compression"],
                           compression_level=journal["compression_level"], encoding=journal["encoding"])
    try:
        for begin in journal["begins"]:
            layouts = [_layout(entry) for entry in begin["layouts"]]
            attributes = {key: run_attributes[key] for key in begin["attributes"]}
            changed = [key for key, text in begin["attributes"].items() if canonical(attributes[key]) != text]
            if changed:  # set twice with different values: the replay cannot know the first value
                raise InputError(f"cannot merge the parts in '{parts[0].parent}': attribute(s) {changed} "
                                 "were changed by a later renderer; use resume_chunk_keypoints: 0")
            writer.begin(len(keypoints), layouts, {key: _read_all(parts, key) for key in begin["records"]},
                         attributes)
            first = 0
            for path in parts:
                with h5py.File(path, "r") as part:
                    first += _replay_keypoints(writer, part, first, layouts)
            writer.end()
        (merged,) = writer.finalize(scene_records, {key: run_attributes[key] for key in journal["attributes"]})
        return merged
    except BaseException:
        writer.abort()
        raise


def remove_empty_staging(folder: Path) -> None:
    """After a failed or interrupted staged run: delete the staging folder when no part was completed (a
    run that failed before finishing one part leaves nothing behind); completed parts are kept for the
    rerun to resume from."""
    if folder.is_dir() and not folder.is_symlink() and not any(folder.glob("scene_*_chunk_*.hdf5")):
        shutil.rmtree(folder, ignore_errors=True)


def remove_staging(folder: Path) -> None:
    """Delete the staging folder once its parts are merged (also temporary files of killed attempts)."""
    if folder.is_dir() and not folder.is_symlink():
        shutil.rmtree(folder)
