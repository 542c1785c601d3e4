"""A stop request (SIGTERM) that outlives the exception which announces it.

The run's SIGTERM handler raises ``SystemExit`` wherever the main thread happens to be. When that is inside a
finalizer (``__del__``, a weak-reference callback, a garbage-collection pass), Python prints "Exception
ignored" and carries on: the run would go on and finish, sealing its output, as if no signal had come
(measured: about 1 in 20-35 SIGTERMs of a many-keypoint run). So the handler also records the request here,
and the loops that commit work (:func:`hybridgen.render.keypoint_loop.run_keypoints` before each keypoint and
before the sinks finish) call :func:`raise_if_requested`, which raises the same ``SystemExit`` again.

Standard library only, imported by every layer.
"""
from __future__ import annotations

_requested: list[int] = []  # the exit status asked for, at most one entry


def request_stop(exit_status: int) -> None:
    """Record a stop request with ``exit_status`` and raise ``SystemExit(exit_status)``."""
    if not _requested:
        _requested.append(exit_status)
    raise SystemExit(exit_status)


def raise_if_requested() -> None:
    """Raise ``SystemExit`` with the recorded status if a stop was requested (and perhaps swallowed)."""
    if _requested:
        raise SystemExit(_requested[0])


def clear() -> None:
    """Forget the request (the block that handles stop requests has ended)."""
    _requested.clear()
