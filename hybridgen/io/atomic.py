"""Atomic output files: write under an unpredictable temporary name in the same folder, then rename
(docs/conventions.md, outputs).

Temporary files are created with :func:`tempfile.mkstemp` (``O_CREAT | O_EXCL``, mode 0600, a random
part in the name), so a symlink planted where a temporary file will be can never redirect a write: a
fresh name is never an existing file. Every temporary file this process still owns is listed, so a
signal handler can delete them (:func:`remove_live_temporaries`). Output paths built from config values
go through :func:`confined_path` (no ``..``, no absolute paths, no NUL, names the filesystem accepts).
"""
from __future__ import annotations

import errno
import os
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

from ..errors import InputError
from ..stop_request import deferred

TEMP_SUFFIX = ".incomplete"
_RANDOM_PART = 8 + 2  # mkstemp's random characters plus the dots around them
_LIVE: set[Path] = set()
_LISTING = threading.RLock()
"""Held while a temporary file is listed and made, and while the listed ones are deleted: a signal handler (main
thread) deleting them waits for another thread's file to exist; re-entrant, for one that lands in the main thread's
own making."""
_PRUNE_AT = 4096


def name_max(directory: Path) -> int:
    """The longest file name (bytes) the filesystem of ``directory`` (or its nearest existing parent) accepts."""
    for folder in (directory, *directory.parents):
        try:
            return int(os.pathconf(folder, "PC_NAME_MAX"))
        except (OSError, ValueError):
            continue
    return 255


def check_file_name(path: Path) -> Path:
    """``path`` if its name is valid here (no NUL, not too long for the filesystem); else one-line InputError."""
    text = str(path)
    if "\0" in text:
        raise InputError(f"output path {text!r} contains a NUL character")
    limit = name_max(path.parent)
    if len(os.fsencode(path.name)) > limit:
        raise InputError(f"output file name '{path.name[:40]}...' is {len(os.fsencode(path.name))} bytes; this "
                         f"filesystem allows {limit}")
    return path


def confined_path(output_dir: str | Path, relative: str | Path, what: str = "path") -> Path:
    """``output_dir / relative``, refusing anything that would leave ``output_dir``: absolute paths, ``..``
    parts, NUL characters, symlinked parents pointing outside, and names the filesystem cannot hold."""
    text = str(relative)
    if "\0" in text or "\0" in str(output_dir):
        raise InputError(f"{what} {text!r} contains a NUL character")
    rel = Path(text)
    if rel.is_absolute() or ".." in rel.parts or text.strip() == "":
        raise InputError(f"{what} must be a relative path inside output_dir without '..', got {text!r}")
    base = Path(output_dir)
    target = base / rel
    resolved_base = base.resolve()
    if not target.resolve().is_relative_to(resolved_base):
        raise InputError(f"{what} {text!r} leads outside output_dir '{base}' (through a symlink)")
    for part in rel.parts:
        check_file_name(base / part)
    return target


def temporary_path(final: Path) -> Path:
    """A new, empty, private file beside ``final`` to write into until it is complete (hidden, same
    filesystem; its name is ``.<final name>.<random>.incomplete``, shortened to fit the filesystem).

    The caller renames it with :func:`commit` or deletes it (:func:`discard`); files left behind by a
    killed process are ignored by readers (hidden, ``.incomplete``)."""
    final = check_file_name(Path(final))
    room = name_max(final.parent) - _RANDOM_PART - len(TEMP_SUFFIX) - 1
    stem = os.fsdecode(os.fsencode(final.name)[:room]) if room > 0 else ""
    if len(_LIVE) >= _PRUNE_AT:
        _LIVE.difference_update([p for p in _LIVE if not os.path.lexists(p)])
    # The name is listed before the file exists: a signal handler that deletes the live files (a worker's
    # SIGTERM exits at once, between any two bytecodes, from the main thread while another writes) can never
    # miss a file that exists. A stop request of the main process (SystemExit) waits for the descriptor to close.
    with deferred():
        try:
            return _created(final.parent, f".{stem}.")
        except UnicodeError:  # cut inside a multi-byte character: drop the final name from the temp name
            return _created(final.parent, ".")


def _created(folder: Path, prefix: str) -> Path:
    """A new empty file ``<prefix><random><TEMP_SUFFIX>`` in ``folder``, made as :func:`tempfile.mkstemp` makes
    its files (its random names, ``O_CREAT | O_EXCL | O_NOFOLLOW``, mode 0600), listed in the live temporaries
    before it is created."""
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    names = tempfile._get_candidate_names()  # mkstemp's own source of random names
    for _ in range(tempfile.TMP_MAX):
        temp = folder / f"{prefix}{next(names)}{TEMP_SUFFIX}"
        with _LISTING:
            _LIVE.add(temp)
            try:
                fd = os.open(temp, flags, 0o600)
            except FileExistsError:  # taken (or a planted symlink): another name
                _LIVE.discard(temp)
                continue
            except OSError as exc:
                _LIVE.discard(temp)
                raise InputError(f"cannot write in '{folder}': {exc.strerror or exc}") from None
            except BaseException:
                _LIVE.discard(temp)
                raise
        os.close(fd)
        return temp
    raise InputError(f"cannot write in '{folder}': no free temporary file name")


def discard(temp: Path) -> None:
    """Delete a temporary file (if it is still there), then forget it (in that order: a signal handler that
    deletes the live files in between finds it listed)."""
    try:
        os.unlink(temp)
    except FileNotFoundError:
        pass
    _LIVE.discard(temp)


def close_discarded_hdf5(h5: Any) -> None:
    """Close the open h5py file ``h5`` whose temporary file is being given up, without the close writing to
    the disk: its descriptor is first pointed at an anonymous in-memory file (Linux ``memfd``), so what HDF5
    still flushes while closing (dirty metadata, cached chunks) cannot fail on a full disk. A close whose
    flush failed leaves HDF5 with half-closed datasets, and closing them again - h5py's ``File.close``
    retries, as does a later file's close or the process's exit - crashed the process (SIGSEGV in
    ``H5D_close``, HDF5 2.0). The caller deletes the temporary file. Never raises."""
    try:
        if not h5.id.valid:
            return
        fd = h5.id.get_vfd_handle()
        if isinstance(fd, int) and fd >= 0 and hasattr(os, "memfd_create"):
            sink = os.memfd_create("hybridgen-discarded")
            try:
                os.dup2(sink, fd)
            finally:
                os.close(sink)
    except Exception:  # another driver, a closed file: close it as it is
        pass
    try:
        h5.close()
    except Exception:
        pass


@contextmanager
def hdf5_temporary(temp: Path, mode: str = "w", **options: Any) -> Iterator[Any]:
    """``h5py.File(temp, mode, **options)`` for a temporary file (:func:`temporary_path`), closed on leaving;
    on an error inside, closed by :func:`close_discarded_hdf5` and deleted. A close that fails is not tried
    again (the file is deleted and the error raised). The caller commits ``temp`` after leaving."""
    import h5py

    try:
        h5 = h5py.File(temp, mode, **options)
    except BaseException:
        discard(temp)
        raise
    try:
        yield h5
    except BaseException:
        close_discarded_hdf5(h5)
        discard(temp)
        raise
    try:
        h5.close()
    except BaseException:
        discard(temp)
        raise


def remove_live_temporaries() -> int:
    """Delete every temporary file this process created and has not committed; returns how many.
    Safe to call from a signal handler's exit path."""
    removed = 0
    with _LISTING:
        for temp in list(_LIVE):
            try:
                os.unlink(temp)
                removed += 1
            except OSError:
                pass
        _LIVE.clear()
    return removed


def prepare_output_dir(directory: Path) -> Path:
    """Create ``directory`` (and parents); a clear error if it is a file or not writable."""
    if "\0" in str(directory):
        raise InputError(f"output directory {str(directory)!r} contains a NUL character")
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
    """Flush ``temp`` to disk and rename it to ``final`` (atomic on POSIX within one filesystem).
    A full disk is one line (InputError) and the temporary file is deleted."""
    if final.is_dir():
        discard(temp)
        raise InputError(f"cannot write '{final}': a directory has that name")
    try:
        with open(temp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(temp, final)
    except OSError as exc:
        discard(temp)
        if exc.errno == errno.ENOSPC:
            raise InputError(f"no space left on the device writing '{final}'") from None
        raise InputError(f"cannot write '{final}': {exc.strerror or exc}") from None
    _LIVE.discard(temp)
