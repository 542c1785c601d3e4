"""Work units as Ray tasks (:class:`hybridgen.run.executor.Executor` on a Ray cluster). Ray is imported when
this executor is chosen; a local cluster started here binds 127.0.0.1 only and is stopped with the run."""
from __future__ import annotations

import logging
import os
import socket
from concurrent.futures import Future
from contextlib import contextmanager
from typing import Any, Iterator

from ..errors import InputError, SystemSetupError, printable
from ..logs import LOGGER
from .executor import Executor
from .ray_loopback import keep_ray_on_loopback
from .signals import reclaim_sigterm
from .unit_task import UnitTask
from .units import WorkUnit

RAY_CONNECT_TIMEOUT_S = 10.0


def check_reachable(address: str) -> None:
    """One line instead of a hang when a Ray address (``host:port`` or ``ray://host:port``) answers nothing."""
    if address in ("auto", "local"):
        return
    hostport = address.split("://", 1)[-1].rsplit("/", 1)[0]
    host, _, port = hostport.rpartition(":")
    if not host or not port.isdigit():
        raise InputError(f"--address must be host:port or ray://host:port, got {address!r}")
    try:
        socket.create_connection((host, int(port)), timeout=RAY_CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        raise InputError(f"cannot reach the Ray cluster at {address} within {RAY_CONNECT_TIMEOUT_S:.0f} s: "
                         f"{exc.strerror or exc}") from None


CANCEL_WAIT_S = 30.0
"""How long an interrupted run waits for its cancelled Ray units to abort their writers (s)."""


def _run(task: UnitTask, unit: WorkUnit) -> tuple[int, int]:
    try:
        return task(unit)
    except BaseException as exc:
        raise _utf8_safe(exc)  # same exception, same chain; only its texts changed


def _utf8_safe(exc: BaseException) -> BaseException:
    """``exc`` and the exceptions chained to it with every text that holds non-UTF-8 bytes of a file name shown as
    ``\\xNN`` (:func:`hybridgen.errors.printable`). Ray sends a task's error as a UTF-8 string and its worker died
    (WorkerCrashedError, a traceback instead of the user's one line) on the surrogate escapes of a Latin-1 path."""
    pending: list[BaseException | None] = [exc]
    seen: set[int] = set()
    while pending:
        current = pending.pop()
        if current is None or id(current) in seen:
            continue
        seen.add(id(current))
        current.args = tuple(printable(a) if isinstance(a, str) else a for a in current.args)
        for name in ("filename", "filename2"):
            value = getattr(current, name, None)
            if isinstance(value, str):
                setattr(current, name, printable(value))
        pending += [current.__cause__, current.__context__]
    return exc


def _unwrapped(remote: Future) -> Future:
    """A future of ``remote``'s result whose error is the unit's own exception: Ray raises a RayTaskError subclass of
    it whose text holds the worker's traceback, so a user's InputError would print as a traceback instead of its
    one line (as a pool run prints it)."""
    local: Future = Future()

    def settle(done: Future) -> None:
        error = done.exception()
        if error is None:
            local.set_result(done.result())
        else:
            cause = getattr(error, "cause", None)
            local.set_exception(cause if isinstance(cause, BaseException) else error)

    remote.add_done_callback(settle)
    return local


@contextmanager
def _printable_entrypoint(ray: Any) -> Iterator[None]:
    """While Ray starts, its record of the driver's command line (``ray._private.utils.get_entrypoint_name``, read
    from /proc) with non-UTF-8 bytes of file names as ``\\xNN``: Ray stores it in a UTF-8 string and raised
    UnicodeEncodeError for a Latin-1 path argument. The units receive the real paths (pickled, not encoded)."""
    utils = getattr(getattr(ray, "_private", None), "utils", None)
    original = getattr(utils, "get_entrypoint_name", None)
    if original is None:  # another Ray version: nothing to wrap
        yield
        return
    utils.get_entrypoint_name = lambda: printable(original())
    try:
        yield
    finally:
        utils.get_entrypoint_name = original


class RayExecutor(Executor):
    """Runs units as Ray tasks (each Ray worker process keeps its GL context and Mitsuba between tasks)."""

    def __init__(self, task: UnitTask, address: str | None, workers: int) -> None:
        try:
            import ray
        except ImportError:
            raise SystemSetupError("--executor ray needs Ray: `.venv/bin/pip install 'ray[default]'`") from None
        self.ray = ray
        self.started = False
        if not ray.is_initialized():
            threads = str(max(1, (os.cpu_count() or 1) // workers))
            runtime_env = {"env_vars": {"LP_NUM_THREADS": threads, "HYBRIDGEN_THREADS": threads}}
            # Ray's own start-up lines (INFO, the token-authentication WARNING) only with -v: an error stays one line
            quiet = {"logging_level": logging.DEBUG if LOGGER.getEffectiveLevel() <= logging.DEBUG else logging.ERROR}
            with _printable_entrypoint(ray):
                if address:
                    check_reachable(address)
                    ray.init(address=address, include_dashboard=False, log_to_driver=False, runtime_env=runtime_env,
                             **quiet)
                else:
                    keep_ray_on_loopback()  # _node_ip_address alone is overridden by Ray (see ray_loopback.py)
                    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False,
                             runtime_env=runtime_env, _node_ip_address="127.0.0.1", **quiet)
            self.started = True
            reclaim_sigterm()  # ray.init replaced it with a handler that exits without stopping the cluster
        self.remote = ray.remote(_run)
        self.task = task
        self.in_flight: set[Any] = set()  # ObjectRefs of the units submitted and not finished

    def submit(self, unit: WorkUnit) -> Future:
        ref = self.remote.remote(self.task, unit)
        self.in_flight.add(ref)
        future = ref.future()
        future.add_done_callback(lambda _: self.in_flight.discard(ref))
        return _unwrapped(future)

    def shutdown(self, interrupted: bool = False) -> None:
        if interrupted and self.in_flight:
            # units still running stop as on Ctrl-C (KeyboardInterrupt in the task: their writers abort and remove
            # their temporary files) before the cluster goes; a killed worker would leave them behind
            refs = list(self.in_flight)
            for ref in refs:
                self.ray.cancel(ref, force=False)
            self.ray.wait(refs, num_returns=len(refs), timeout=CANCEL_WAIT_S)
        if self.started:
            self.ray.shutdown()
