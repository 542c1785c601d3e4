"""Sharded runs: work units executed in this process, on a process pool or on Ray; crash-safe, verified
resume.

Units are (scene, keypoint chunk) pairs (:mod:`hybridgen.run.units`). Each writes its own complete file
``<output_dir>/shards/scene_SSSSSS_chunk_CCCCC.hdf5`` under a temporary name and renames it when done. Every
shard carries the run's fingerprint (:mod:`hybridgen.run.fingerprint`) and a digest of its content
(:mod:`hybridgen.io.integrity`). Rerunning the same command resumes: a shard is reused only when its
fingerprint equals this run's and its content verifies; an unreadable, truncated, empty or damaged shard
counts as missing and is rendered again; a shard made by another config or other inputs stops the run with
one line naming the differing keys (``--restart`` discards the folder's shards, ``--force-resume`` keeps
shards that verify whatever made them).

How many chunks a scene has is known once its first chunk ran (it records ``scene_keypoints``). Units are
generated lazily and at most ``2 x workers`` are in flight, so memory does not grow with
``number_of_scenes``; pool workers are replaced after ``max_tasks_per_child`` units (bounded growth of
long runs). When every unit of every scene exists, ``<output_dir>/data.hdf5`` is (re)built over them
(:mod:`hybridgen.run.shard_index`). ``--shard i/N`` runs only the scenes with ``scene % N == i``, for
external schedulers (SLURM arrays, indexed jobs); the run that completes the last unit builds the index.
Results never depend on how units are spread over workers.
"""
from __future__ import annotations

import os
import socket
import time
from collections import deque
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

import h5py

from ..config.config_file import ConfigFile, load_config
from ..errors import ConfigError, InputError, SystemSetupError
from ..io.atomic import prepare_output_dir
from ..io.integrity import verify
from ..modules.base import Module
from .fingerprint import FINGERPRINT_ATTR, describe_difference, differing_keys, parse_fingerprint
from .scene_reuse import SceneReuse
from .signals import die_with_parent, reclaim_sigterm
from .units import SHARD_FOLDER, WorkUnit, chunk_count

EXECUTORS = ("pool", "ray")
DEFAULT_MAX_TASKS_PER_CHILD = 25
RAY_CONNECT_TIMEOUT_S = 10.0


@dataclass(frozen=True)
class ShardingPlan:
    """How a config splits into units and where their files go (``<output_dir>/<folder>``). ``staged``: a
    non-sharded run whose units are merged into one ordinary file at the end
    (:mod:`hybridgen.run.staged_output`) instead of indexed."""

    scenes: int
    chunk_size: int
    output_dir: Path
    file_name: str
    folder: str = SHARD_FOLDER
    staged: bool = False

    def unit(self, scene: int, chunk: int = 0) -> WorkUnit:
        """The plan's unit of ``scene``, ``chunk``."""
        return WorkUnit(scene, chunk, self.chunk_size, self.folder)


@dataclass(frozen=True)
class ResumePolicy:
    """What to do with existing outputs: ``restart`` discards them, ``force`` keeps intact ones made by
    another config; ``fingerprint`` is this run's (JSON text) and the dict it encodes."""

    fingerprint_text: str
    fingerprint: dict[str, str]
    restart: bool = False
    force: bool = False


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


def limit_threads(threads: int, parent_pid: int | None = None) -> None:
    """Give this worker process ``threads`` CPU threads for rasterizing (llvmpipe) and path tracing (Dr.Jit),
    so that several workers share the cores instead of oversubscribing them. Call before rendering.
    With ``parent_pid`` (pool workers) the process also stops when that parent does (see
    :func:`hybridgen.run.signals.die_with_parent`)."""
    os.environ["LP_NUM_THREADS"] = str(threads)  # read by Mesa when the GL context is created
    os.environ["HYBRIDGEN_THREADS"] = str(threads)
    if parent_pid is not None:
        die_with_parent(parent_pid)


def _apply_thread_limit() -> None:
    threads = os.environ.get("HYBRIDGEN_THREADS", "")
    if threads.isdigit():
        import drjit

        if drjit.thread_count() != int(threads):
            drjit.set_thread_count(int(threads))


def run_unit(path: str, args: Sequence[str], env: Mapping[str, str] | None, unit: WorkUnit,
             fingerprint: str | None = None, progress: Callable[[int, str], Any] | None = None,
             scenes: "SceneReuse | None" = None) -> tuple[int, int]:
    """Run one unit (in whatever process this is); returns (keypoints rendered, keypoints of its scene).
    ``fingerprint`` (the parent's, JSON) is recorded in the unit's file; ``progress`` makes progress bars
    (units run in this process); with ``scenes`` consecutive units of one scene build it once
    (:mod:`hybridgen.run.scene_reuse`)."""
    from .pipeline import build_modules, execute

    _apply_thread_limit()
    attributes = {FINGERPRINT_ATTR: fingerprint} if fingerprint is not None else None
    if scenes is not None:
        context = scenes.execute(path, args, env, unit, attributes=attributes, progress=progress)
    else:
        config = load_config(path, args, env)
        context = execute(config, build_modules(config), unit=unit, attributes=attributes, progress=progress)
    return context.frames_rendered, len(context.scene.camera)


def _scene_keypoints(shard: Path) -> int:
    with h5py.File(shard, "r") as h5:
        return int(h5.attrs["scene_keypoints"])


def check_existing(path: Path, policy: ResumePolicy, log: Callable[[str], None]) -> bool:
    """Whether the output at ``path`` can be reused: True when it verifies and was made by this run's
    fingerprint (or ``policy.force``); False when it is missing or damaged (it is rendered again); a
    one-line InputError when it is intact but was made by something else."""
    if not path.exists() and not path.is_symlink():
        return False
    problem = verify(path)
    if problem is not None:
        log(f"{path}: {problem}; rendering it again")
        return False
    with h5py.File(path, "r") as h5:
        stored = parse_fingerprint(h5.attrs.get(FINGERPRINT_ATTR))
    keys = differing_keys(stored, policy.fingerprint)
    if not keys or policy.force:
        return True
    raise InputError(f"'{path}' was made by a different config or different inputs (differs: "
                     f"{describe_difference(keys)}); rerun with --restart to discard the existing output, or "
                     "--force-resume to keep it")


def discard_outputs(plan: ShardingPlan, shard: tuple[int, int] | None = None) -> int:
    """``--restart``: delete the plan's shards (with ``shard`` ``(i, n)``: only those of scenes ``s % n == i``)
    and the index; returns how many files were removed."""
    removed = 0
    shards = plan.output_dir / plan.folder
    candidates = list(shards.glob("scene_*_chunk_*.hdf5")) if shards.is_dir() else []
    if shard is not None:
        candidates = [p for p in candidates if p.name[6:12].isdigit() and int(p.name[6:12]) % shard[1] == shard[0]]
    for path in [*candidates, plan.output_dir / plan.file_name]:
        if path.is_file() or path.is_symlink():
            path.unlink()
            removed += 1
    return removed


class _Local:
    """Runs units one after another in this process."""

    def __init__(self, task: Callable[[WorkUnit], tuple[int, int]], scenes: SceneReuse | None = None) -> None:
        self.task = task
        self.scenes = scenes

    def submit(self, unit: WorkUnit) -> Future:
        future: Future = Future()
        try:
            future.set_result(self.task(unit))
        except BaseException as exc:  # surfaced by the scheduler
            if isinstance(exc, (KeyboardInterrupt, SystemExit)):
                raise
            future.set_exception(exc)
        return future

    def shutdown(self, interrupted: bool = False) -> None:
        if self.scenes is not None:
            self.scenes.close()


class _Pool:
    """A spawn-context process pool whose workers die with this process and are replaced after
    ``max_tasks_per_child`` units."""

    def __init__(self, call: tuple[Any, ...], workers: int, max_tasks_per_child: int) -> None:
        threads = max(1, (os.cpu_count() or 1) // workers)
        self.call = call
        self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"), initializer=limit_threads,
                                        initargs=(threads, os.getpid()), max_tasks_per_child=max_tasks_per_child)

    def submit(self, unit: WorkUnit) -> Future:
        return self.pool.submit(run_unit, *self.call[:3], unit, self.call[3])

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


def _check_reachable(address: str) -> None:
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


class _Ray:
    """Runs units as Ray tasks (each Ray worker process keeps its GL context and Mitsuba between tasks).
    A local cluster started here binds 127.0.0.1 only and is stopped with the run."""

    def __init__(self, call: tuple[Any, ...], address: str | None, workers: int) -> None:
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
                _check_reachable(address)
                ray.init(address=address, include_dashboard=False, log_to_driver=False, runtime_env=runtime_env)
            else:
                ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, runtime_env=runtime_env,
                         _node_ip_address="127.0.0.1")
            self.started = True
            reclaim_sigterm()  # ray.init replaced it with a handler that exits without stopping the cluster
        self.remote = ray.remote(run_unit)
        self.call = call

    def submit(self, unit: WorkUnit) -> Future:
        return self.remote.remote(*self.call[:3], unit, self.call[3]).future()

    def shutdown(self, interrupted: bool = False) -> None:
        if self.started:
            self.ray.shutdown()


def _scene_units(plan: ShardingPlan, index: int, count: int) -> Iterator[WorkUnit]:
    for scene in range(index, plan.scenes, count):
        yield plan.unit(scene)


def run_sharded(plan: ShardingPlan, path: str | Path, args: Sequence[str], env: Mapping[str, str] | None, *,
                workers: int, shard: tuple[int, int] | None, executor: str, address: str | None,
                log: Callable[[str], None], start: float, policy: ResumePolicy,
                max_tasks_per_child: int = DEFAULT_MAX_TASKS_PER_CHILD,
                progress: Callable[[int, str], Any] | None = None) -> Any:
    """Execute the plan's missing units, then build the index (or merge a staged plan's parts) when all
    exist. ``progress`` makes progress bars of units run in this process. Returns a RunSummary."""
    from .pipeline import RunSummary

    if executor not in EXECUTORS:
        raise InputError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    if max_tasks_per_child < 1:
        raise InputError(f"--max-tasks-per-child must be >= 1, got {max_tasks_per_child}")
    index, count = shard or (0, 1)
    if not 0 <= index < count:
        raise InputError(f"--shard i/N needs 0 <= i < N, got {index}/{count}")
    prepare_output_dir(plan.output_dir / plan.folder)
    if (plan.output_dir / plan.file_name).is_dir():
        raise InputError(f"'{plan.output_dir / plan.file_name}' is a directory; the index cannot be written there")
    if policy.restart:
        removed = discard_outputs(plan, shard)
        if removed:
            log(f"--restart: discarded {removed} existing file(s)")
    call = (str(path), list(args), dict(env) if env is not None else None, policy.fingerprint_text)
    if executor == "ray":
        pool: Any = _Ray(call, address, workers)
    elif workers == 1:
        scenes = SceneReuse() if plan.staged else None  # a staged run's parts share one scene
        pool = _Local(lambda unit: run_unit(*call[:3], unit, call[3], progress, scenes), scenes)
    else:
        pool = _Pool(call, workers, max_tasks_per_child)
    scene_units = _scene_units(plan, index, count)
    ready: deque[WorkUnit] = deque()  # later chunks of scenes whose first chunk is known
    pending: dict[Future, WorkUnit] = {}
    window = 2 * workers
    frames = skipped = 0

    def expand(unit: WorkUnit, total: int) -> None:
        chunks = range(1, chunk_count(total, plan.chunk_size))
        ready.extend(plan.unit(unit.scene, chunk) for chunk in chunks)

    def refill() -> None:
        nonlocal skipped
        while len(pending) < window:
            unit = ready.popleft() if ready else next(scene_units, None)
            if unit is None:
                return
            target = unit.shard_path(plan.output_dir)
            if check_existing(target, policy, log):
                skipped += 1
                if unit.chunk == 0:
                    expand(unit, _scene_keypoints(target))
                continue
            pending[pool.submit(unit)] = unit

    interrupted = True
    try:
        refill()
        while pending:
            done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
            for future in done:
                unit = pending.pop(future)
                rendered, total = future.result()
                frames += rendered
                log(f"unit {unit.name}: {rendered} keypoint(s)")
                if unit.chunk == 0:
                    expand(unit, total)
            refill()
        interrupted = False
    finally:
        pool.shutdown(interrupted)
    outputs = []
    shards = complete_shards(plan)
    if shards is not None and plan.staged:
        from .staged_output import consolidate, remove_staging

        outputs.append(consolidate(plan.output_dir / plan.file_name, shards))
        remove_staging(plan.output_dir / plan.folder)
    elif shards is not None:
        from .shard_index import build_index

        outputs.append(build_index(plan.output_dir / plan.file_name, shards, policy.fingerprint_text))
    else:
        log(f"shard {index}/{count} done; data.hdf5 is built once every scene's units exist")
    if skipped:
        log(f"resumed: {skipped} unit(s) were already complete and verified")
    return RunSummary(frames, time.perf_counter() - start, outputs)


def complete_shards(plan: ShardingPlan) -> list[Path] | None:
    """Every unit file of every scene in (scene, chunk) order, or None while some are missing."""
    shards = []
    for scene in range(plan.scenes):
        first = plan.unit(scene).shard_path(plan.output_dir)
        if not first.is_file():
            return None
        for chunk in range(chunk_count(_scene_keypoints(first), plan.chunk_size)):
            path = plan.unit(scene, chunk).shard_path(plan.output_dir)
            if not path.is_file():
                return None
            shards.append(path)
    return shards
