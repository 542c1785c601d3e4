"""Sharded runs: work units executed in this process, on a process pool or on Ray; crash-safe and resumable.

Units are (scene, keypoint chunk) pairs (:mod:`hybridgen.run.units`). Each writes its own complete file
``<output_dir>/shards/scene_SSSSSS_chunk_CCCCC.hdf5`` under a temporary name and renames it when done; a
unit whose file exists is complete and skipped, so rerunning the same command resumes after a crash or a
kill. How many chunks a scene has is known once its first chunk ran (it records ``scene_keypoints``).
When every unit of every scene exists, ``<output_dir>/data.hdf5`` is (re)built over them
(:mod:`hybridgen.run.shard_index`). ``--shard i/N`` runs only the scenes with ``scene % N == i``, for
external schedulers (SLURM arrays, indexed jobs); the run that completes the last unit builds the index.
Results never depend on how units are spread over workers.
"""
from __future__ import annotations

import os
import time
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import h5py

from ..config.config_file import ConfigFile, load_config
from ..errors import ConfigError, InputError, SystemSetupError
from ..modules.base import Module
from .units import WorkUnit, chunk_count

EXECUTORS = ("pool", "ray")


@dataclass(frozen=True)
class ShardingPlan:
    """How a config splits into units and where their files go."""

    scenes: int
    chunk_size: int
    output_dir: Path
    file_name: str


def sharding_plan(config: ConfigFile, modules: list[Module], force: bool = False) -> ShardingPlan | None:
    """The plan of a config that runs as units (several scenes, chunks, or ``force``); None otherwise."""
    initializer = next((m for m in modules if m.module_name == "main.Initializer"), None)
    scenes = initializer.config["number_of_scenes"] if initializer else 1
    chunk_size = initializer.config["keypoints_per_chunk"] if initializer else 0
    if scenes == 1 and chunk_size == 0 and not force:
        return None
    writers = [m for m in modules if m.module_name == "writer.Hdf5Writer"]
    if len(writers) != 1 or writers[0].config["layout"] != "single":
        raise ConfigError("a sharded run (several scenes, keypoint chunks, --workers or --shard) needs exactly one "
                          "writer.Hdf5Writer with layout: single", file=config.path, key="modules")
    writer = writers[0].config
    return ShardingPlan(scenes, chunk_size, Path(writer["output_dir"]), writer["file_name"])


def limit_threads(threads: int) -> None:
    """Give this worker process ``threads`` CPU threads for rasterizing (llvmpipe) and path tracing (Dr.Jit),
    so that several workers share the cores instead of oversubscribing them. Call before rendering."""
    os.environ["LP_NUM_THREADS"] = str(threads)  # read by Mesa when the GL context is created
    os.environ["HYBRIDGEN_THREADS"] = str(threads)


def _apply_thread_limit() -> None:
    threads = os.environ.get("HYBRIDGEN_THREADS", "")
    if threads.isdigit():
        import drjit

        if drjit.thread_count() != int(threads):
            drjit.set_thread_count(int(threads))


def run_unit(path: str, args: Sequence[str], env: Mapping[str, str] | None, unit: WorkUnit) -> tuple[int, int]:
    """Run one unit (in whatever process this is); returns (keypoints rendered, keypoints of its scene)."""
    from .pipeline import build_modules, execute

    _apply_thread_limit()
    config = load_config(path, args, env)
    context = execute(config, build_modules(config), unit=unit)
    return context.frames_rendered, len(context.scene.camera)


def _scene_keypoints(shard: Path) -> int:
    with h5py.File(shard, "r") as h5:
        return int(h5.attrs["scene_keypoints"])


class _Local:
    """Runs units one after another in this process."""

    def __init__(self, task: Callable[[WorkUnit], tuple[int, int]]) -> None:
        self.task = task

    def submit(self, unit: WorkUnit) -> Future:
        future: Future = Future()
        try:
            future.set_result(self.task(unit))
        except BaseException as exc:  # surfaced by the scheduler
            future.set_exception(exc)
        return future

    def shutdown(self) -> None:
        pass


class _Ray:
    """Runs units as Ray tasks (each Ray worker process keeps its GL context and Mitsuba between tasks)."""

    def __init__(self, path: str, args: Sequence[str], env: Mapping[str, str] | None, address: str | None,
                 workers: int) -> None:
        try:
            import ray
        except ImportError:
            raise SystemSetupError("--executor ray needs Ray: `.venv/bin/pip install 'ray[default]'`") from None
        self.ray = ray
        if not ray.is_initialized():
            threads = str(max(1, (os.cpu_count() or 1) // workers))
            ray.init(address=address, num_cpus=None if address else workers, include_dashboard=False,
                     log_to_driver=False,
                     runtime_env={"env_vars": {"LP_NUM_THREADS": threads, "HYBRIDGEN_THREADS": threads}})
        self.remote = ray.remote(run_unit)
        self.call = (path, list(args), dict(env) if env is not None else None)

    def submit(self, unit: WorkUnit) -> Future:
        return self.remote.remote(*self.call, unit).future()

    def shutdown(self) -> None:
        pass


def run_sharded(plan: ShardingPlan, path: str | Path, args: Sequence[str], env: Mapping[str, str] | None, *,
                workers: int, shard: tuple[int, int] | None, executor: str, address: str | None,
                log: Callable[[str], None], start: float) -> Any:
    """Execute the plan's missing units, then build the index when all exist. Returns a RunSummary."""
    from .pipeline import RunSummary

    if executor not in EXECUTORS:
        raise InputError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    if workers < 1:
        raise InputError(f"--workers must be >= 1, got {workers}")
    index, count = shard or (0, 1)
    if not 0 <= index < count:
        raise InputError(f"--shard i/N needs 0 <= i < N, got {index}/{count}")
    (plan.output_dir / "shards").mkdir(parents=True, exist_ok=True)
    path = str(path)
    if executor == "ray":
        pool: Any = _Ray(path, args, env, address, workers)
    elif workers == 1:
        pool = _Local(lambda unit: run_unit(path, args, env, unit))
    else:
        threads = max(1, (os.cpu_count() or 1) // workers)
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"), initializer=limit_threads,
                                   initargs=(threads,))
    mine = [s for s in range(plan.scenes) if s % count == index]
    pending: dict[Future, WorkUnit] = {}
    frames = skipped = 0

    def schedule(unit: WorkUnit) -> None:
        nonlocal skipped
        if unit.shard_path(plan.output_dir).exists():
            skipped += 1
            if unit.chunk == 0:
                expand(unit.scene, _scene_keypoints(unit.shard_path(plan.output_dir)))
            return
        future = pool.submit(unit) if not isinstance(pool, ProcessPoolExecutor) else \
            pool.submit(run_unit, path, list(args), dict(env) if env is not None else None, unit)
        pending[future] = unit

    def expand(scene: int, total: int) -> None:
        for chunk in range(1, chunk_count(total, plan.chunk_size)):
            schedule(WorkUnit(scene, chunk, plan.chunk_size))

    try:
        for scene in mine:
            schedule(WorkUnit(scene, 0, plan.chunk_size))
        while pending:
            done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
            for future in done:
                unit = pending.pop(future)
                rendered, total = future.result()
                frames += rendered
                log(f"unit {unit.name}: {rendered} keypoint(s)")
                if unit.chunk == 0:
                    expand(unit.scene, total)
    finally:
        pool.shutdown()
    outputs = []
    shards = complete_shards(plan)
    if shards is not None:
        from .shard_index import build_index

        outputs.append(build_index(plan.output_dir / plan.file_name, shards))
    else:
        log(f"shard {index}/{count} done; data.hdf5 is built once every scene's units exist")
    if skipped:
        log(f"resumed: {skipped} unit(s) were already complete")
    return RunSummary(frames, time.perf_counter() - start, outputs)


def complete_shards(plan: ShardingPlan) -> list[Path] | None:
    """Every unit file of every scene in (scene, chunk) order, or None while some are missing."""
    shards = []
    for scene in range(plan.scenes):
        first = WorkUnit(scene, 0, plan.chunk_size).shard_path(plan.output_dir)
        if not first.exists():
            return None
        for chunk in range(chunk_count(_scene_keypoints(first), plan.chunk_size)):
            path = WorkUnit(scene, chunk, plan.chunk_size).shard_path(plan.output_dir)
            if not path.exists():
                return None
            shards.append(path)
    return shards
