"""Sharded runs: scheduling work units on an executor (:mod:`hybridgen.run.executor`: this process, a process
pool or Ray); crash-safe, verified resume.

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

import dataclasses
import time
from collections import deque
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

import h5py

from .. import stop_request
from ..config.config_file import ConfigFile
from ..errors import InputError
from ..io.atomic import prepare_output_dir
from ..io.integrity import verify
from ..logs import Log
from .executor import (DEFAULT_MAX_TASKS_PER_CHILD, EXECUTORS, Executor, InProcessExecutor, PoolExecutor)
from .fingerprint import FINGERPRINT_ATTR, describe_difference, differing_keys, parse_fingerprint
from .plan import ShardingPlan
from .unit_task import UnitTask
from .units import WorkUnit, chunk_count


@dataclass
class RunSummary:
    """What a finished run made."""

    frames: int
    seconds: float
    outputs: list[Path]


@dataclass(frozen=True)
class ResumePolicy:
    """What to do with existing outputs: ``restart`` discards them, ``force`` keeps intact ones made by
    another config; ``fingerprint`` is this run's (JSON text) and the dict it encodes."""

    fingerprint_text: str
    fingerprint: dict[str, str]
    restart: bool = False
    force: bool = False


def check_executor_options(kind: str, max_tasks_per_child: int) -> None:
    """One line for an unknown executor kind or a pool that would never replace its workers."""
    if kind not in EXECUTORS:
        raise InputError(f"executor must be one of {EXECUTORS}, got {kind!r}")
    if max_tasks_per_child < 1:
        raise InputError(f"--max-tasks-per-child must be >= 1, got {max_tasks_per_child}")


def open_executor(kind: str, task: UnitTask, *, workers: int, address: str | None = None,
                  max_tasks_per_child: int = DEFAULT_MAX_TASKS_PER_CHILD,
                  progress: Callable[[int, str], Any] | None = None, reuse_scenes: bool = False,
                  log: Log | None = None, config: ConfigFile | None = None) -> Executor:
    """The executor ``kind`` (checked by :func:`check_executor_options`; ``pool``: this process for one
    worker, else a process pool; ``ray``: Ray at ``address`` or a local cluster) for ``workers`` parallel
    units of ``task``. Units run in this process report to ``log``; pool workers log through
    :func:`hybridgen.logs.log_line`, set up as this process is. ``config``: the task's config, already
    loaded here (units reusing scenes in this process then do not parse it again)."""
    if kind == "ray":
        from .executor_ray import RayExecutor

        return RayExecutor(task, address, workers)
    if workers == 1:
        return InProcessExecutor(task, progress, reuse_scenes, log, config)
    return PoolExecutor(task, workers, max_tasks_per_child)


def _scene_keypoints(shard: Path) -> int:
    with h5py.File(shard, "r") as h5:
        return int(h5.attrs["scene_keypoints"])


def check_existing(path: Path, policy: ResumePolicy, log: Log) -> bool:
    """Whether the output at ``path`` can be reused: True when it verifies and was made by this run's
    fingerprint (or ``policy.force``); False when it is missing or damaged (it is rendered again); a
    one-line InputError when it is intact but was made by something else."""
    if not path.exists() and not path.is_symlink():
        return False
    problem = verify(path)
    if problem is not None:
        log(f"{path}: {problem}; rendering it again", "notice")
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


def _scene_units(plan: ShardingPlan, index: int, count: int) -> Iterator[WorkUnit]:
    for scene in range(index, plan.scenes, count):
        yield plan.unit(scene)


def run_sharded(plan: ShardingPlan, path: str | Path, args: Sequence[str], env: Mapping[str, str] | None, *,
                workers: int, shard: tuple[int, int] | None, executor: str, address: str | None,
                log: Log, start: float, policy: ResumePolicy,
                max_tasks_per_child: int = DEFAULT_MAX_TASKS_PER_CHILD,
                progress: Callable[[int, str], Any] | None = None, config: ConfigFile | None = None) -> RunSummary:
    """Execute the plan's missing units, then build the index (or merge a staged plan's parts) when all
    exist. ``progress`` makes progress bars of units run in this process; ``config``: the one at ``path``
    with ``args`` and ``env``, already loaded by the caller."""
    check_executor_options(executor, max_tasks_per_child)
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
    whole = None
    if plan.staged:  # where a run of one part writes its file (scene_reuse.py); one left by a killed run is stale
        whole = dataclasses.replace(plan.unit(0), whole=True).shard_path(plan.output_dir)
        whole.unlink(missing_ok=True)
    task = UnitTask(str(path), tuple(args), dict(env) if env is not None else None, policy.fingerprint_text)
    pool = open_executor(executor, task, workers=workers, address=address, max_tasks_per_child=max_tasks_per_child,
                         progress=progress, reuse_scenes=plan.staged, log=log,  # staged: parts share one scene
                         config=config)
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
            stop_request.raise_if_requested()  # a SIGTERM whose SystemExit a finalizer swallowed
            done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
            for future in done:
                unit = pending.pop(future)
                rendered, total = future.result()
                frames += rendered
                log(f"unit {unit.name}: {rendered} keypoint(s)")
                if unit.chunk == 0:
                    expand(unit, total)
            refill()
        stop_request.raise_if_requested()  # nothing is consolidated or indexed after a stop request
        interrupted = False
    finally:
        pool.shutdown(interrupted)
        if interrupted and plan.staged:
            from .staged_output import remove_empty_staging

            remove_empty_staging(plan.output_dir / plan.folder)
    outputs = []
    shards = None if whole is not None and whole.is_file() else complete_shards(plan)
    if whole is not None and whole.is_file():  # a staged run's only part wrote the run's file itself
        from .staged_output import remove_staging

        outputs.append(whole.replace(plan.output_dir / plan.file_name))
        remove_staging(plan.output_dir / plan.folder)
    elif shards is not None and plan.staged:
        from .staged_output import consolidate, remove_staging

        outputs.append(consolidate(plan.output_dir / plan.file_name, shards))
        remove_staging(plan.output_dir / plan.folder)
    elif shards is not None:
        from .shard_index import build_index

        outputs.append(build_index(plan.output_dir / plan.file_name, shards, policy.fingerprint_text))
    else:
        log(f"shard {index}/{count} done; data.hdf5 is built once every scene's units exist")
    if skipped:
        log(f"resumed: {skipped} unit(s) were already complete and verified", "notice")
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
