"""What made an output: the resolved config, the hybridgen version and the input files' contents.

A fingerprint is a flat JSON object stored as the ``fingerprint`` attribute of every HDF5 file a run
writes. Its keys are

- ``hybridgen_version``;
- ``config:<module>#<index>.<key path>`` for every leaf of the resolved config (after ``<args:N>`` and
  environment substitution). Keys in :data:`IGNORED_KEYS` are left out: ``output_dir`` (where a run writes
  does not change what it writes, so a moved output folder still resumes) and ``render_threads`` (how many
  raster threads compute the labels; the values are the same, ``tests/render/test_threaded_labels.py``), so
  a run resumes with another thread count;
- ``input:<path>`` -> SHA-256 of each file the config names: a string value that is an existing file, a
  glob that matches files, or the files directly in a named folder (relative to the working directory,
  else to the config's folder, as modules read them), plus the MTL files an OBJ names and the texture
  files an MTL names. ``<path>`` is relative to the config's folder when the file lies below it, so a
  moved checkout gives the same fingerprint. Hashes are remembered by file identity
  (:mod:`hybridgen.run.input_hashes`), so a rerun reads only inputs that changed.

:func:`differing_keys` names what changed between two fingerprints, so a refused resume says which
config keys or input files differ.
"""
from __future__ import annotations

import glob
import hashlib
import json
import os
from pathlib import Path
from typing import Any, Iterator

from .._version import __version__
from ..config.config_file import ConfigFile
from ..io.mesh_references import referenced_files
from .input_hashes import InputHashes

FINGERPRINT_ATTR = "fingerprint"
IGNORED_KEYS = ("output_dir", "render_threads")
"""Config keys that change where or how a run computes, not what it writes (left out of the fingerprint)."""
MAX_FOLDER_FILES = 10_000  # files hashed per named folder
_LONG_VALUE = 200  # leaf values longer than this (in JSON) are stored as their SHA-256


def _leaves(value: Any, prefix: str) -> Iterator[tuple[str, Any]]:
    if isinstance(value, dict):
        for key, item in value.items():
            if str(key) in IGNORED_KEYS:
                continue
            yield from _leaves(item, f"{prefix}.{key}" if prefix else str(key))
    elif isinstance(value, list) and any(isinstance(item, (dict, list)) for item in value):
        for index, item in enumerate(value):
            yield from _leaves(item, f"{prefix}[{index}]")
    else:
        yield prefix, value


def _leaf_text(value: Any) -> str:
    text = json.dumps(value, sort_keys=True, default=str)
    return text if len(text) <= _LONG_VALUE else "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def _candidate_files(text: str, folder: Path) -> list[Path]:
    if "\0" in text or len(text) > 4096:
        return []
    try:
        path = Path(text).expanduser()
        if not path.exists() and (folder / path).exists():
            path = folder / path  # modules fall back to the config's folder (docs/conventions.md section 5)
        if path.is_file():
            return [path]
        if path.is_dir():
            with os.scandir(path) as entries:  # file types from the listing: no stat per file
                names = sorted(e.name for e in entries if e.is_file() and not e.name.startswith("."))
            return [path / name for name in names[:MAX_FOLDER_FILES]]
    except (OSError, ValueError):
        return []
    if any(c in text for c in "*?["):
        return [Path(p) for p in sorted(glob.glob(text, recursive=True))[:MAX_FOLDER_FILES] if Path(p).is_file()]
    return []


def _input_key(path: Path, folder: Path, resolved_folders: dict[Path, Path]) -> str:
    """``path`` relative to the config's folder when it lies below it (so a moved checkout or dataset
    folder gives the same fingerprint, and the same bytes), else as the config names it. The files of one
    folder resolve it once (``resolved_folders``); a file that is a symlink resolves to its target."""
    try:
        if path.is_symlink():
            resolved = path.resolve()
        else:
            parent = resolved_folders.get(path.parent)
            if parent is None:
                parent = resolved_folders[path.parent] = path.parent.resolve()
            resolved = parent / path.name
        return str(resolved.relative_to(folder))
    except (OSError, ValueError):
        return str(path)


def input_files(config: ConfigFile) -> list[Path]:
    """Every input file the config names (and the MTL / texture files those name), each once, in order."""
    seen: dict[str, Path] = {}
    folder = Path(config.path).resolve().parent
    queue = [path for _, value in _leaves(config.resolved, "") if isinstance(value, str)
             for path in _candidate_files(value, folder)]
    while queue:
        path = queue.pop(0)
        key = str(path)
        if key in seen or not path.is_file():
            continue
        seen[key] = path
        try:
            queue.extend(referenced_files(path))
        except OSError:
            pass
    return list(seen.values())


def _config_leaves(config: ConfigFile) -> Iterator[tuple[str, Any]]:
    for key, value in config.resolved.items():
        if key == "modules" and isinstance(value, list):
            for index, entry in enumerate(value):
                name = entry.get("name", "?") if isinstance(entry, dict) else "?"
                body = entry.get("config", {}) if isinstance(entry, dict) else entry
                yield from _leaves(body, f"{name}#{index}")
        else:
            yield from _leaves(value, str(key))


def run_fingerprint(config: ConfigFile, hashes: InputHashes | None = None) -> dict[str, str]:
    """The fingerprint of a run of ``config`` (see the module documentation); input files are hashed through
    ``hashes`` (default: the cache in hybridgen's cache folder), which is saved afterwards."""
    hashes = InputHashes.default() if hashes is None else hashes
    fingerprint = {"hybridgen_version": __version__}
    for key, value in _config_leaves(config):
        fingerprint[f"config:{key}"] = _leaf_text(value)
    folder = Path(config.path).resolve().parent
    resolved_folders: dict[Path, Path] = {}
    for path in input_files(config):
        try:
            fingerprint[f"input:{_input_key(path, folder, resolved_folders)}"] = hashes.sha256(path)
        except OSError:
            continue  # the module that reads it reports the problem
    hashes.save()
    return fingerprint


def fingerprint_text(fingerprint: dict[str, str]) -> str:
    """The stored form: JSON with sorted keys (so equal fingerprints are equal bytes)."""
    return json.dumps(fingerprint, sort_keys=True, separators=(",", ":"))


def parse_fingerprint(value: Any) -> dict[str, str] | None:
    """A stored fingerprint attribute back as a dict (None when absent or not one)."""
    if value is None:
        return None
    try:
        parsed = json.loads(value.decode() if isinstance(value, bytes) else str(value))
    except (ValueError, UnicodeDecodeError):
        return None
    return parsed if isinstance(parsed, dict) else None


def differing_keys(old: dict[str, str] | None, new: dict[str, str]) -> list[str]:
    """The keys whose values differ (or exist in only one), without the ``config:`` prefix."""
    if old is None:
        return ["fingerprint (the file has none: made by an older hybridgen or another tool)"]
    keys = sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k))
    return [k.removeprefix("config:") for k in keys]


def describe_difference(keys: list[str], limit: int = 6) -> str:
    """``a, b, c and 4 more`` for a one-line message."""
    shown = ", ".join(keys[:limit])
    return shown + (f" and {len(keys) - limit} more" if len(keys) > limit else "")
