"""Stopping a run cleanly on SIGTERM / SIGINT, in the main process and in worker processes.

The main process turns SIGTERM into ``SystemExit(143)`` and SIGINT into ``KeyboardInterrupt`` (exit 130 from
the CLI): both unwind through the run's ``finally`` blocks, which stop the workers, abort the writers and
delete this process's temporary files. Workers ignore SIGINT (a Ctrl-C at a terminal reaches the whole
process group; the parent decides), delete their temporary files and exit at once on SIGTERM, and ask the
kernel to send them SIGTERM when their parent dies (``PR_SET_PDEATHSIG``, Linux), so even a SIGKILLed
parent leaves no worker behind.
"""
from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
from contextlib import contextmanager
from types import FrameType
from typing import Iterator

from .. import stop_request
from ..io.atomic import remove_live_temporaries

EXIT_SIGTERM = 128 + signal.SIGTERM  # 143
EXIT_SIGINT = 128 + signal.SIGINT  # 130
_PR_SET_PDEATHSIG = 1
_ACTIVE: list[bool] = []  # stop_on_signals blocks in progress


def _terminate(signum: int, frame: FrameType | None) -> None:
    stop_request.request_stop(EXIT_SIGTERM)  # recorded too: a SystemExit raised inside a finalizer is lost


def _interrupt(signum: int, frame: FrameType | None) -> None:
    stop_request.request_stop(EXIT_SIGINT)  # KeyboardInterrupt, as Python's handler, but deferrable


@contextmanager
def stop_on_signals() -> Iterator[None]:
    """In the main thread: SIGTERM raises ``SystemExit(143)`` and SIGINT ``KeyboardInterrupt`` for the block,
    again at the next keypoint if the first one was swallowed, and only after a :func:`hybridgen.stop_request.deferred`
    block ends (:mod:`hybridgen.stop_request`); on any interruption this process's temporary files are deleted.
    Elsewhere (threads) nothing is installed."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    previous_int = signal.getsignal(signal.SIGINT)
    if previous_int is signal.default_int_handler:  # an ignored SIGINT (nohup, a parent's choice) stays ignored
        signal.signal(signal.SIGINT, _interrupt)
    stop_request.clear()
    _ACTIVE.append(True)
    try:
        yield
    except (KeyboardInterrupt, SystemExit):
        remove_live_temporaries()
        raise
    finally:
        _ACTIVE.pop()
        signal.signal(signal.SIGTERM, previous)
        if previous_int is signal.default_int_handler:
            signal.signal(signal.SIGINT, previous_int)
        stop_request.clear()


def reclaim_sigterm() -> None:
    """Install the run's SIGTERM handler again, after a library replaced it (``ray.init`` installs its own,
    which exits with status 15 without unwinding the run)."""
    if threading.current_thread() is threading.main_thread() and signal.getsignal(signal.SIGTERM) is not _terminate:
        if _ACTIVE:
            signal.signal(signal.SIGTERM, _terminate)


def _worker_terminate(signum: int, frame: FrameType | None) -> None:
    remove_live_temporaries()
    os._exit(EXIT_SIGTERM)


def die_with_parent(parent_pid: int) -> None:
    """Worker process setup: SIGTERM when the parent (``parent_pid``) dies (Linux), SIGTERM deletes
    temporary files and exits, SIGINT is left to the parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _worker_terminate)
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        except (OSError, AttributeError):
            pass
        if os.getppid() != parent_pid:  # the parent died before prctl took effect
            _worker_terminate(signal.SIGTERM, None)
