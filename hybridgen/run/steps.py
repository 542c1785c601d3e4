"""A config's modules in one process: build them (every module validated first, order and keys checked from
their declarations), then prepare and run them in order on a run context."""
from __future__ import annotations

from typing import Any, Callable, Mapping

from ..config.config_file import ConfigFile
from ..config.paths import resolve_module_paths
from ..config.registry import get_module
from ..config.schema import validate_config
from ..errors import ConfigError, HybridgenError, closest
from ..input_paths import config_folder
from ..logs import Log
from ..modules.base import Module
from .context import RunContext
from .plan import check_keys, check_order
from .units import WorkUnit


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
    check_order(modules, config.path)
    declared = {p.name for m in modules for p in m.params}
    for key in config.global_all:
        if key not in declared:
            raise ConfigError(f"no module of this config takes this key{closest(key, sorted(declared))}",
                              file=config.path, key=f"global.all.{key}")
    check_keys(modules, config.path)
    return modules


def execute(config: ConfigFile, modules: list[Module], *, unit: WorkUnit | None = None,
            progress: Callable[[int, str], Any] | None = None,
            log: Log | None = None, attributes: Mapping[str, Any] | None = None) -> RunContext:
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
