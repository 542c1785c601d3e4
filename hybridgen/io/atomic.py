"""Atomic output files: write under a temporary name in the same folder, then rename (docs/conventions.md section 4)."""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError

TEMP_SUFFIX = ".incomplete"


def temporary_path(final: Path) -> Path:
    """The name a file is written under until it is complete: hidden, same folder, same filesystem."""
    return final.with_name(f".{final.name}.{os.getpid()}{TEMP_SUFFIX}")


def prepare_output_dir(directory: Path) -> Path:
    """Create ``directory`` (and parents); a clear error if it is a file or not writable."""
    if directory.exists() and not directory.is_dir():
        raise InputError(f"output directory '{directory}' exists and is not a directory")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create output directory '{directory}': {exc.strerror}") from None
    if not os.access(directory, os.W_OK | os.X_OK):
        raise InputError(f"output directory '{directory}' is not writable")
    return directory


def commit(temp: Path, final: Path) -> None:
    """Flush ``temp`` to disk and rename it to ``final`` (atomic on POSIX within one filesystem)."""
    with open(temp, "rb+") as handle:
        os.fsync(handle.fileno())
    os.replace(temp, final)
