"""One writer per output folder: an advisory ``fcntl.flock`` on ``<output_dir>/.hybridgen.lock``.

A run holds the lock of every writer's folder from before its first module runs until it ends
(:func:`output_locks`); a second run into the same folder gets one line naming the holder's pid and host.
Writers that append to a folder (COCO, BlenderProc layout, BOP) also hold it themselves
(:func:`hold_output_lock`) from the moment they read the existing ids and file numbers until they commit or
abort, so users of the Python API are protected too. Inside one process the lock is re-entrant (counted).

``flock`` is advisory and, on most network filesystems, only seen by one machine's kernel (NFS emulates it
with ``fcntl`` locks since Linux 2.6.12); the lock file records ``pid host`` for the message. The file is
removed on release; a process that acquired the lock checks that it locked the file still at that name,
so removal never lets two holders in.
"""
from __future__ import annotations

import errno
import fcntl
import os
import time
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Callable, Iterable, Iterator

from ..errors import InputError
from .atomic import prepare_output_dir

LOCK_NAME = ".hybridgen.lock"
_HELD: dict[str, list[int]] = {}  # real path of the lock file -> [fd, depth]


HOLDER_WAIT = 1.0
"""Seconds a refused run waits for the holder's ``pid host`` line: a run that has just taken the lock writes it
right after (two runs started a moment apart read the new, still empty file)."""


def _holder(path: Path) -> str:
    """``pid N on HOST`` from the lock file, read again for up to :data:`HOLDER_WAIT` seconds while it holds no
    such line yet."""
    deadline = time.monotonic() + HOLDER_WAIT
    while True:
        try:
            text = path.read_text(encoding="utf-8", errors="replace").split()
        except OSError:
            text = []
        if len(text) >= 2 and text[0].isdigit():
            return f"pid {text[0]} on {text[1]}"
        if time.monotonic() >= deadline:
            return "its pid and host not recorded yet"
        time.sleep(0.01)


def _acquire(path: Path, wait: bool, shared: bool) -> int:
    mode = (fcntl.LOCK_SH if shared else fcntl.LOCK_EX) | (0 if wait else fcntl.LOCK_NB)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise InputError(f"cannot lock output folder '{path.parent}': {exc.strerror or exc}") from None
        try:
            fcntl.flock(fd, mode)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise InputError(f"output folder '{path.parent}' is in use by another hybridgen run "
                                 f"({_holder(path)}); wait for it to finish or use another output_dir") from None
            raise InputError(f"cannot lock output folder '{path.parent}': {exc.strerror or exc}") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(path, follow_symlinks=False).st_ino
        except FileNotFoundError:
            same = False
        if same:  # the line is written over the old one, then cut to length: never an empty file between
            line = f"{os.getpid()} {os.uname().nodename}\n".encode()  # nodename = socket.gethostname()
            os.pwrite(fd, line, 0)
            os.ftruncate(fd, len(line))
            return fd
        os.close(fd)  # the previous holder removed the file after we opened it: lock the new one


def _enter(directory: str | Path, wait: bool, name: str = LOCK_NAME, shared: bool = False) -> tuple[str, Path]:
    folder = prepare_output_dir(Path(directory))
    path = folder / name
    key = os.path.realpath(path)
    if key in _HELD:
        _HELD[key][1] += 1
    else:
        _HELD[key] = [_acquire(path, wait, shared), 1]
    return key, path


def _leave(key: str, path: Path) -> None:
    held = _HELD[key]
    held[1] -= 1
    if held[1] == 0:
        del _HELD[key]
        try:  # remove the file only when nobody else holds it (shared holders: an exclusive try first)
            fcntl.flock(held[0], fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.unlink(path)
        except OSError:
            pass
        os.close(held[0])


@contextmanager
def output_lock(directory: str | Path, *, wait: bool = False, name: str = LOCK_NAME,
                shared: bool = False) -> Iterator[Path]:
    """Hold the advisory lock ``name`` of ``directory`` (created if missing) for the ``with`` block;
    ``shared``: several shared holders may hold it together, never with an exclusive one."""
    key, path = _enter(directory, wait, name, shared)
    try:
        yield path.parent
    finally:
        _leave(key, path)


@contextmanager
def output_locks(directories: Iterable[str | Path], shard: tuple[int, int] | None = None) -> Iterator[None]:
    """Hold the locks of several folders (each once, in a fixed order so two runs cannot deadlock).

    With ``shard`` ``(i, n)`` (``hybridgen run --shard i/n``, tasks of one array job writing one folder
    together) the folder lock is shared and ``.hybridgen.lock.shard-i-of-n`` exclusive: the tasks run side
    by side, but not with a run without ``--shard`` nor with a second task of the same index."""
    unique = sorted({os.path.realpath(d) for d in directories})
    with ExitStack() as stack:
        for directory in unique:
            stack.enter_context(output_lock(directory, shared=shard is not None))
            if shard is not None:
                stack.enter_context(output_lock(directory, name=f"{LOCK_NAME}.shard-{shard[0]}-of-{shard[1]}"))
        yield


def held_by_this_process(directory: str | Path) -> bool:
    """Whether this process holds ``directory``'s lock (writers use it to check they commit under it)."""
    return os.path.realpath(Path(directory) / LOCK_NAME) in _HELD


def hold_output_lock(directory: str | Path) -> Callable[[], None]:
    """Take ``directory``'s lock now (one line if another run holds it) and return the function that
    releases it (calling it again does nothing): for writers that hand out ids and file names from their
    constructor to their commit."""
    key, path = _enter(directory, wait=False)
    released = False

    def release() -> None:
        nonlocal released
        if not released:
            released = True
            _leave(key, path)

    return release
