"""Executes a config: validate every module first, then run them in order, then commit outputs."""
from __future__ import annotations

import errno
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

from ..config.config_file import ConfigFile, load_config
from ..config.paths import config_folder, resolve_module_paths
from ..config.registry import get_module
from ..config.schema import validate_config
from ..errors import ConfigError, HybridgenError, InputError
from ..io.atomic import prepare_output_dir
from ..io.output_lock import output_locks
from ..modules.base import Module
from .context import RunContext
from .fingerprint import FINGERPRINT_ATTR, fingerprint_text, run_fingerprint
from .runner import DEFAULT_MAX_TASKS_PER_CHILD, ShardingPlan
from .signals import stop_on_signals
from .units import WorkUnit


@dataclass
class RunSummary:
    """What a finished run made."""

    frames: int
    seconds: float
    outputs: list[Path]


def build_modules(config: ConfigFile) -> list[Module]:
    """Instantiate every module with a validated config; errors name file, module and key."""
    modules: list[Module] = []
    for entry in config.modules:
        try:
            cls = get_module(entry.name)
            values = validate_config(cls.param_table(), entry.config, config.global_all)
            resolve_module_paths(cls.params, values, config.path)
        except ConfigError as exc:
            raise exc.located(file=config.path, module=entry.name, index=entry.index) from None
        modules.append(cls(values, entry.index))
    _check_order(modules, config.path)
    declared = {p.name for m in modules for p in m.params}
    for key in config.global_all:
        if key not in declared:
            raise ConfigError(f"no module of this config takes this key{_suggest(key, declared)}",
                              file=config.path, key=f"global.all.{key}")
    return modules


def _suggest(key: str, known: set[str]) -> str:
    from ..config.schema import closest

    return closest(key, sorted(known))


def _check_order(modules: list[Module], file: str) -> None:
    """Writers collect what renderers before them made: a renderer after the last writer would be lost."""
    renderers = [m for m in modules if m.module_name.startswith("renderer.")]
    writers = [m for m in modules if m.module_name.startswith("writer.")]
    if renderers and not writers:
        raise ConfigError("the config renders but has no writer module: add writer.Hdf5Writer after the "
                          "renderer", file=file, module=renderers[-1].module_name, index=renderers[-1].index)
    if renderers and renderers[-1].index > writers[-1].index:
        raise ConfigError(f"renders after the last writer ({writers[-1].module_name}, #{writers[-1].index}); "
                          "move the writer after it", file=file, module=renderers[-1].module_name,
                          index=renderers[-1].index)


def execute(config: ConfigFile, modules: list[Module], *, unit: WorkUnit | None = None,
            progress: Callable[[int, str], Any] | None = None,
            log: Callable[[str], None] | None = None, attributes: Mapping[str, Any] | None = None) -> RunContext:
    """Prepare, then run every module in order (for ``unit``: one work unit of a sharded run).
    ``attributes`` (e.g. the run's ``fingerprint``) are recorded in every output file."""
    context = RunContext(config=config, progress=progress, unit=unit)
    context.attributes.update(attributes or {})
    if log is not None:
        context.log = log
    try:
        run_modules(config, modules, context)
    finally:
        run_cleanups(context)
    return context


def run_modules(config: ConfigFile, modules: list[Module], context: RunContext) -> None:
    """Prepare, then run ``modules`` in order on ``context``; errors name file, module and key."""
    with config_folder(config.path):  # relative input paths fall back to the config's folder
        for phase in ("prepare", "run"):
            for module in modules:
                try:
                    getattr(module, phase)(context)
                except ConfigError as exc:
                    raise exc.located(file=config.path, module=module.module_name, index=module.index) from None
                except HybridgenError as exc:
                    raise type(exc)(f"{config.path}: module '{module.module_name}' (#{module.index}): {exc}") \
                        from None


def run_cleanups(context: RunContext) -> None:
    """Run the cleanups the modules registered on ``context`` (last first) and forget them."""
    for cleanup in reversed(context.cleanups):
        cleanup()
    context.cleanups.clear()


def scene_stage(modules: list[Module]) -> int | None:
    """Where the modules that depend on a work unit's keypoints begin: the index of the first renderer, when
    every module from there on is a renderer or a writer (the modules before it build the scene, the same
    for every unit of a scene); None when there is no renderer or a later module changes the scene."""
    first = next((i for i, m in enumerate(modules) if m.module_name.startswith("renderer.")), None)
    if first is None or not all(m.module_name.startswith(("renderer.", "writer.")) for m in modules[first:]):
        return None
    return first


def writer_folders(modules: list[Module], file: str) -> list[Path]:
    """The output folders of the config's writer modules, created (each is locked for the run); one that
    cannot be is an error naming its module."""
    folders = []
    for module in modules:
        if module.module_name.startswith("writer.") and isinstance(module.config.get("output_dir"), str):
            try:
                folders.append(prepare_output_dir(Path(module.config["output_dir"])))
            except InputError as exc:
                raise ConfigError(str(exc), file=file, module=module.module_name, index=module.index,
                                  key="output_dir") from None
    return folders


@contextmanager
def disk_full_is_one_line(folders: list[Path]) -> Iterator[None]:
    """A full disk (ENOSPC, also as h5py's OSError from a worker) becomes one InputError naming the output
    folder; the writers have already deleted their temporary files."""
    try:
        yield
    except OSError as exc:
        if exc.errno != errno.ENOSPC and "No space left on device" not in str(exc):
            raise
        where = ", ".join(f"'{folder}'" for folder in folders) or "the output folder"
        raise InputError(f"no space left on the device writing into {where}; nothing incomplete was kept under "
                         "a final name (rerun to resume once there is space)") from None


def single_file_output(modules: list[Module]) -> Path | None:
    """The final path of the config's ``writer.Hdf5Writer`` with ``layout: single`` when it is the only
    writer (then an existing file is resumed or refused); None for other configs (appending writers such as
    COCO or BOP make a rerun mean "more data", so their data.hdf5 is rewritten as before)."""
    writers = [m for m in modules if m.module_name.startswith("writer.")]
    if len(writers) != 1 or writers[0].module_name != "writer.Hdf5Writer" or writers[0].config["layout"] != "single":
        return None
    return Path(writers[0].config["output_dir"]) / writers[0].config["file_name"]


def staged_plan(modules: list[Module]) -> ShardingPlan | None:
    """The plan of a non-sharded run that renders in resumable parts (:mod:`hybridgen.run.staged_output`):
    its only writer is ``writer.Hdf5Writer`` (``layout: single``) with ``resume_chunk_keypoints`` > 0 (-1:
    :data:`~hybridgen.run.staged_output.DEFAULT_CHUNK_KEYPOINTS` when it path-traces color)."""
    from .staged_output import DEFAULT_CHUNK_KEYPOINTS, staging_folder_name

    single = single_file_output(modules)
    writer = next((m for m in modules if m.module_name == "writer.Hdf5Writer"), None)
    if single is None or writer is None:
        return None
    chunk = writer.config["resume_chunk_keypoints"]
    if chunk < 0:
        chunk = DEFAULT_CHUNK_KEYPOINTS if any(m.module_name == "renderer.RgbRenderer" for m in modules) else 0
    if chunk == 0:
        return None
    return ShardingPlan(1, chunk, single.parent, single.name, folder=staging_folder_name(single.name), staged=True)


def run_config(path: str | Path, args: Sequence[str] = (), *, env: Mapping[str, str] | None = None,
               progress: Callable[[int, str], Any] | None = None,
               log: Callable[[str], None] | None = None, workers: int = 1, shard: tuple[int, int] | None = None,
               executor: str = "pool", address: str | None = None, restart: bool = False,
               force_resume: bool = False, max_tasks_per_child: int = DEFAULT_MAX_TASKS_PER_CHILD) -> RunSummary:
    """Run the config at ``path`` with command-line ``args`` (``<args:N>``); returns a summary.

    ``progress(total, what)`` makes a progress bar per renderer; ``log`` receives one-line status messages.
    A config with several scenes or keypoint chunks (``main.Initializer``), or ``workers`` > 1, or a
    ``shard`` ``(i, n)`` runs as work units (see :mod:`hybridgen.run.runner`).

    Every writer's folder is locked for the run (a second run into it gets one line). Existing outputs
    are reused only when they verify and carry this run's fingerprint; one made by another config or other
    inputs is an error naming the differing keys unless ``restart`` (discard it) or ``force_resume`` (keep
    it). SIGTERM stops the run (workers included) and exits 143, SIGINT 130; temporary files are deleted.
    """
    from .runner import ResumePolicy, check_existing, run_sharded, sharding_plan

    start = time.perf_counter()
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"--workers must be an integer >= 1, got {workers!r}")
    if restart and force_resume:
        raise InputError("--restart and --force-resume exclude each other")
    say = log or (lambda message: None)
    config = load_config(path, args, env)
    modules = build_modules(config)
    plan = sharding_plan(config, modules, force=workers > 1 or shard is not None)
    fingerprint = run_fingerprint(config)
    policy = ResumePolicy(fingerprint_text(fingerprint), fingerprint, restart=restart, force=force_resume)
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
                "--restart renders it again")
            return RunSummary(0, time.perf_counter() - start, [single])
        staged = staged_plan(modules)
        if staged is not None:  # rendered in verified parts, merged into the same bytes: a killed run resumes
            return run_sharded(staged, path, args, env, workers=1, shard=None, executor="pool", address=None,
                               log=say, start=start, policy=policy, max_tasks_per_child=max_tasks_per_child,
                               progress=progress)
        context = execute(config, modules, progress=progress, log=log,
                          attributes={FINGERPRINT_ATTR: policy.fingerprint_text})
    return RunSummary(context.frames_rendered, time.perf_counter() - start, context.outputs)
