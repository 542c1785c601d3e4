"""Where work units run: one small interface, implemented in this process, on a process pool
(:class:`PoolExecutor`) and on Ray (:mod:`hybridgen.run.executor_ray`). The scheduler
(:func:`hybridgen.run.runner.run_sharded`) opens one (:func:`hybridgen.run.runner.open_executor`), submits
units and shuts it down."""
from __future__ import annotations

import abc
import os
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:  # imported where used: the command line reads EXECUTORS without loading the run machinery
    from ..config.config_file import ConfigFile
    from ..logs import Log
    from .unit_task import UnitTask
    from .units import WorkUnit

EXECUTORS = ("pool", "ray")
DEFAULT_MAX_TASKS_PER_CHILD = 25


class Executor(abc.ABC):
    """Runs work units of one run; each future's result is (keypoints rendered, keypoints of its scene)."""

    @abc.abstractmethod
    def submit(self, unit: WorkUnit) -> Future:
        """Start ``unit``; its future completes when the unit's file is written."""

    @abc.abstractmethod
    def shutdown(self, interrupted: bool = False) -> None:
        """Release the workers: wait for them, or (``interrupted``) stop them now."""


class InProcessExecutor(Executor):
    """Runs units one after another in this process (progress bars shown). With ``reuse_scenes``
    consecutive units of one scene build it once (:mod:`hybridgen.run.scene_reuse`)."""

    def __init__(self, task: UnitTask, progress: Callable[[int, str], Any] | None = None,
                 reuse_scenes: bool = False, log: Log | None = None, config: ConfigFile | None = None) -> None:
        from .scene_reuse import SceneReuse

        self.task = task
        self.progress = progress
        self.log = log
        self.scenes = SceneReuse(config) if reuse_scenes else None  # config: the task's, already loaded

    def submit(self, unit: WorkUnit) -> Future:
        future: Future = Future()
        try:
            future.set_result(self.task(unit, self.progress, self.scenes, self.log))
        except BaseException as exc:  # surfaced by the scheduler
            if isinstance(exc, (KeyboardInterrupt, SystemExit)):
                raise
            future.set_exception(exc)
        return future

    def shutdown(self, interrupted: bool = False) -> None:
        if self.scenes is not None:
            self.scenes.close()


class PoolExecutor(Executor):
    """A spawn-context process pool of ``workers`` processes sharing the cores; they die with this process,
    log as it does (:func:`hybridgen.logs.logging_setup`) and are replaced after ``max_tasks_per_child`` units."""

    def __init__(self, task: UnitTask, workers: int, max_tasks_per_child: int) -> None:
        from concurrent.futures import ProcessPoolExecutor
        from multiprocessing import get_context

        from ..logs import logging_setup
        from .unit_task import start_worker

        threads = max(1, (os.cpu_count() or 1) // workers)
        self.task = task
        self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"), initializer=start_worker,
                                        initargs=(threads, os.getpid(), logging_setup()),
                                        max_tasks_per_child=max_tasks_per_child)

    def submit(self, unit: WorkUnit) -> Future:
        return self.pool.submit(self.task, unit)

    def shutdown(self, interrupted: bool = False) -> None:
        if not interrupted:
            self.pool.shutdown()
            return
        processes = list((self.pool._processes or {}).values())  # noqa: SLF001 - no public handle
        for process in processes:
            if process.is_alive():
                process.terminate()
        for process in processes:
            process.join(timeout=10)
            if process.is_alive():
                process.kill()
                process.join(timeout=5)
        self.pool.shutdown(wait=False, cancel_futures=True)
