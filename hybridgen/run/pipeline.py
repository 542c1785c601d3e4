"""Executes a config: validate every module first, then run them in order (here, or as work units on an
executor when the run is sharded or resumable in parts), then commit outputs."""
from __future__ import annotations

import errno
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

from ..config.config_file import load_config
from ..errors import ENVIRONMENT_ERRNOS, ConfigError, InputError, fault_errno
from ..io.atomic import check_file_name, prepare_output_dir
from ..io.output_lock import output_locks
from ..logs import Log, no_log
from ..modules.base import Module, Role
from .executor import DEFAULT_MAX_TASKS_PER_CHILD
from .fingerprint import FINGERPRINT_ATTR, fingerprint_text, run_fingerprint
from .plan import sharding_plan, single_file_output, staged_plan
from .runner import ResumePolicy, RunSummary, check_existing, run_sharded
from .signals import stop_on_signals
from .steps import build_modules, execute

__all__ = ["build_modules", "execute", "run_config", "RunSummary", "staged_plan"]


def writer_folders(modules: list[Module], file: str) -> list[Path]:
    """The output folders of the config's writer modules, created (each is locked for the run); one that
    cannot be is an error naming its module."""
    folders = []
    for module in modules:
        if module.role is Role.WRITER and isinstance(module.config.get("output_dir"), str):
            try:
                folders.append(prepare_output_dir(Path(module.config["output_dir"])))
            except InputError as exc:
                raise ConfigError(str(exc), file=file, module=module.module_name, index=module.index,
                                  key="output_dir") from None
    return folders


def check_output_names(modules: list[Module], file: str) -> None:
    """A writer's output file name longer than its folder's filesystem allows is an error naming the module
    and its ``file_name`` key (checked before anything looks at the path: the OS refuses it with ENAMETOOLONG)."""
    for module in modules:
        output = module.single_file() if module.role is Role.WRITER else None
        if output is None:
            continue
        try:
            check_file_name(output.path)
        except InputError as exc:
            raise ConfigError(str(exc), file=file, module=module.module_name, index=module.index,
                              key="file_name") from None


@contextmanager
def disk_full_is_one_line(folders: list[Path]) -> Iterator[None]:
    """A full disk (ENOSPC, also as h5py's OSError from a worker) becomes one InputError naming the output
    folder; the writers have already deleted their temporary files."""
    try:
        yield
    except (OSError, RuntimeError) as exc:  # h5py: a failed flush or close is a RuntimeError naming the errno
        number = fault_errno(exc)
        if number is None and "No space left on device" in str(exc):
            number = errno.ENOSPC
        if number not in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            raise
        where = ", ".join(f"'{folder}'" for folder in folders) or "the output folder"
        raise InputError(f"{ENVIRONMENT_ERRNOS[number]} writing into {where}; nothing incomplete was kept under "
                         "a final name (rerun to resume once there is space)") from None


def run_config(path: str | Path, args: Sequence[str] = (), *, env: Mapping[str, str] | None = None,
               progress: Callable[[int, str], Any] | None = None,
               log: Log | None = None, workers: int = 1, shard: tuple[int, int] | None = None,
               executor: str = "pool", address: str | None = None, restart: bool = False,
               force_resume: bool = False, max_tasks_per_child: int = DEFAULT_MAX_TASKS_PER_CHILD) -> RunSummary:
    """Run the config at ``path`` with command-line ``args`` (``<args:N>``); returns a summary.

    ``progress(total, what)`` makes a progress bar per renderer; ``log`` receives one-line status messages with
    their level (:class:`hybridgen.logs.Log`: ``log(message)``, ``log(message, "warning")``).
    A config with several scenes or keypoint chunks (its setup module's ``scene_units``), or ``workers`` > 1, or a
    ``shard`` ``(i, n)`` runs as work units (see :mod:`hybridgen.run.runner`).

    Every writer's folder is locked for the run (a second run into it gets one line). Existing outputs
    are reused only when they verify and carry this run's fingerprint; one made by another config or other
    inputs is an error naming the differing keys unless ``restart`` (discard it) or ``force_resume`` (keep
    it). SIGTERM stops the run (workers included) and exits 143, SIGINT 130; temporary files are deleted.
    """
    start = time.perf_counter()
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"--workers must be an integer >= 1, got {workers!r}")
    if restart and force_resume:
        raise InputError("--restart and --force-resume exclude each other")
    say = log or no_log
    config = load_config(path, args, env)
    modules = build_modules(config)
    plan = sharding_plan(config, modules, force=workers > 1 or shard is not None)
    fingerprint = run_fingerprint(config)
    policy = ResumePolicy(fingerprint_text(fingerprint), fingerprint, restart=restart, force=force_resume)
    check_output_names(modules, config.path)
    single = single_file_output(modules)
    if single is not None and single.is_dir():
        raise InputError(f"'{single}' is a directory; the output file cannot be written there")
    folders = writer_folders(modules, config.path)
    with stop_on_signals(), output_locks(folders, shard), disk_full_is_one_line(folders):
        if plan is not None:
            return run_sharded(plan, path, args, env, workers=workers, shard=shard, executor=executor,
                               address=address, log=say, start=start, policy=policy,
                               max_tasks_per_child=max_tasks_per_child)
        if single is not None and not restart and check_existing(single, policy, say):
            say(f"'{single}' is complete and verified (same config and inputs): nothing to do; "
                "--restart renders it again", "notice")
            return RunSummary(0, time.perf_counter() - start, [single])
        staged = staged_plan(modules)
        if staged is not None:  # rendered in verified parts, merged into the same bytes: a killed run resumes
            return run_sharded(staged, path, args, env, workers=1, shard=None, executor="pool", address=None,
                               log=say, start=start, policy=policy, max_tasks_per_child=max_tasks_per_child,
                               progress=progress, config=config)
        context = execute(config, modules, progress=progress, log=log,
                          attributes={FINGERPRINT_ATTR: policy.fingerprint_text})
    return RunSummary(context.frames_rendered, time.perf_counter() - start, context.outputs)
