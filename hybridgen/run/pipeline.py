"""Executes a config: validate every module first, then run them in order, then commit outputs."""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from ..config.config_file import ConfigFile, load_config
from ..config.registry import get_module
from ..config.schema import validate_config
from ..errors import ConfigError, HybridgenError
from ..modules.base import Module
from .context import RunContext
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
            log: Callable[[str], None] | None = None) -> RunContext:
    """Prepare, then run every module in order (for ``unit``: one work unit of a sharded run)."""
    context = RunContext(config=config, progress=progress, unit=unit)
    if log is not None:
        context.log = log
    try:
        for phase in ("prepare", "run"):
            for module in modules:
                try:
                    getattr(module, phase)(context)
                except ConfigError as exc:
                    raise exc.located(file=config.path, module=module.module_name, index=module.index) from None
                except HybridgenError as exc:
                    raise type(exc)(f"{config.path}: module '{module.module_name}' (#{module.index}): {exc}") \
                        from None
    finally:
        for cleanup in reversed(context.cleanups):
            cleanup()
    return context


def run_config(path: str | Path, args: Sequence[str] = (), *, env: Mapping[str, str] | None = None,
               progress: Callable[[int, str], Any] | None = None,
               log: Callable[[str], None] | None = None, workers: int = 1, shard: tuple[int, int] | None = None,
               executor: str = "pool", address: str | None = None) -> RunSummary:
    """Run the config at ``path`` with command-line ``args`` (``<args:N>``); returns a summary.

    ``progress(total, what)`` makes a progress bar per renderer; ``log`` receives one-line status messages.
    A config with several scenes or keypoint chunks (``main.Initializer``), or ``workers`` > 1, or a
    ``shard`` ``(i, n)`` runs as work units (see :mod:`hybridgen.run.runner`).
    """
    from .runner import run_sharded, sharding_plan

    start = time.perf_counter()
    config = load_config(path, args, env)
    modules = build_modules(config)
    plan = sharding_plan(config, modules, force=workers > 1 or shard is not None)
    if plan is not None:
        return run_sharded(plan, path, args, env, workers=workers, shard=shard, executor=executor, address=address,
                           log=log or (lambda message: None), start=start)
    context = execute(config, modules, progress=progress, log=log)
    return RunSummary(context.frames_rendered, time.perf_counter() - start, context.outputs)
