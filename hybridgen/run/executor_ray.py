"""Work units as Ray tasks (:class:`hybridgen.run.executor.Executor` on a Ray cluster). Ray is imported when
this executor is chosen; a local cluster started here binds 127.0.0.1 only and is stopped with the run."""
from __future__ import annotations

import os
import socket
from concurrent.futures import Future

from ..errors import InputError, SystemSetupError
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


def _run(task: UnitTask, unit: WorkUnit) -> tuple[int, int]:
    return task(unit)


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
            if address:
                check_reachable(address)
                ray.init(address=address, include_dashboard=False, log_to_driver=False, runtime_env=runtime_env)
            else:
                keep_ray_on_loopback()  # _node_ip_address alone is overridden by Ray (see ray_loopback.py)
                ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, runtime_env=runtime_env,
                         _node_ip_address="127.0.0.1")
            self.started = True
            reclaim_sigterm()  # ray.init replaced it with a handler that exits without stopping the cluster
        self.remote = ray.remote(_run)
        self.task = task

    def submit(self, unit: WorkUnit) -> Future:
        return self.remote.remote(self.task, unit).future()

    def shutdown(self, interrupted: bool = False) -> None:
        if self.started:
            self.ray.shutdown()
