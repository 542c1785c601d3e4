"""A stop request (SIGTERM) that outlives the exception which announces it, and blocks it must not interrupt.

The run's SIGTERM handler raises ``SystemExit`` wherever the main thread happens to be. Two places need more:

- **Finalizers.** When the ``SystemExit`` is raised inside a finalizer (``__del__``, a weak-reference
  callback, a garbage-collection pass), Python prints "Exception ignored" and carries on: the run would go on
  and finish, sealing its output, as if no signal had come (measured: about 1 in 20-35 SIGTERMs of a
  many-keypoint run). So the handler also records the request here, and the loops that commit work
  (:func:`hybridgen.render.keypoint_loop.run_keypoints` before each keypoint and before the sinks finish) call
  :func:`raise_if_requested`, which raises the same ``SystemExit`` again.
- **C code that calls back into Python without checking for errors.** moderngl's program creation builds its
  uniform and attribute objects by calling Python functions of its ``_moderngl`` helper and uses the result
  unchecked: a ``SystemExit`` raised in that callback crashed the process with SIGSEGV instead of exit 143
  (measured: about 1 in 15 SIGTERMs of a run compiling programs per scene). Such calls run inside
  :func:`deferred`: there the handler only records the request, and it is raised when the block ends.

Standard library only, imported by every layer.
"""
from __future__ import annotations

import threading
from contextlib import contextmanager
from typing import Iterator

_requested: list[int] = []  # the exit status asked for, at most one entry
_deferring = [0]  # depth of the main thread's deferred() blocks


INTERRUPTED = 130
"""The exit status of SIGINT (128 + 2): its request is raised as ``KeyboardInterrupt``, as Python's own
SIGINT handler does; every other status as ``SystemExit(status)``."""


def _stop(exit_status: int) -> BaseException:
    return KeyboardInterrupt() if exit_status == INTERRUPTED else SystemExit(exit_status)


def request_stop(exit_status: int) -> None:
    """Record a stop request with ``exit_status`` and raise it (``SystemExit(exit_status)``; ``KeyboardInterrupt``
    for :data:`INTERRUPTED`), unless the main thread is inside :func:`deferred` (then the block raises it when
    it ends)."""
    if not _requested:
        _requested.append(exit_status)
    if _deferring[0] == 0:
        raise _stop(exit_status)


def raise_if_requested() -> None:
    """Raise the recorded stop request, if there is one (perhaps swallowed where it was first raised)."""
    if _requested:
        raise _stop(_requested[0])


@contextmanager
def deferred() -> Iterator[None]:
    """A block a stop request must not interrupt (a call into C code that calls back into Python and does not
    check the result): a request arriving inside is recorded and raised when the outermost block ends
    normally. Only the main thread defers (signal handlers run there); elsewhere it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _deferring[0] += 1
    try:
        yield
    finally:
        _deferring[0] -= 1
    if _deferring[0] == 0:
        raise_if_requested()


def clear() -> None:
    """Forget the request (the block that handles stop requests has ended)."""
    _requested.clear()
