"""Reading a config file in the paper's shape: ``setup`` / ``global`` / ``modules`` (docs/conventions.md section 5)."""
from __future__ import annotations

from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any, Mapping, Sequence

import yaml

from ..errors import ConfigError
from .placeholders import resolve_placeholders
from .schema import closest
from .yaml_safety import MAX_CONFIG_BYTES, load_yaml, read_limited

TOP_LEVEL_KEYS = ("setup", "global", "modules", "version")


class _StrictLoader(yaml.SafeLoader):
    """YAML's safe loader, except that a key repeated in one mapping is an error (YAML says so; PyYAML
    would silently keep the last value)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:  # type: ignore[override]
        seen: dict[Any, Any] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)  # type: ignore[no-untyped-call]
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r} (first at line {seen[key].line + 1})", key_node.start_mark)
            seen[key] = key_node.start_mark
        return super().construct_mapping(node, deep=deep)


@dataclass
class ModuleEntry:
    """One ``modules`` list item: its registered name, its own config and its position (0-based)."""

    name: str
    config: dict[str, Any]
    index: int


@dataclass
class ConfigFile:
    """A parsed, placeholder-resolved config."""

    path: str
    text: str
    setup: dict[str, Any] = field(default_factory=dict)
    global_all: dict[str, Any] = field(default_factory=dict)
    modules: list[ModuleEntry] = field(default_factory=list)
    resolved: dict[str, Any] = field(default_factory=dict)

    def resolved_yaml(self) -> str:
        """The full config after placeholder substitution, as YAML text."""
        return yaml.safe_dump(self.resolved, sort_keys=False)


def load_config(path: str | Path, args: Sequence[str] = (), env: Mapping[str, str] | None = None) -> ConfigFile:
    """Parse ``path``, check its shape, resolve placeholders and the ``setup.pip`` requirements."""
    file = str(path)
    try:
        text = read_limited(path, MAX_CONFIG_BYTES, "config file").decode("utf-8")
    except FileNotFoundError:
        raise ConfigError("config file not found", file=file) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read config file: {exc}", file=file) from None
    try:
        raw = load_yaml(text, _StrictLoader, file)  # bounded depth and alias expansion (yaml_safety)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"malformed YAML{where}: {problem}", file=file) from None
    if not isinstance(raw, dict):
        raise ConfigError(f"a config is a mapping with keys {list(TOP_LEVEL_KEYS)}, got {type(raw).__name__}",
                          file=file)
    for key in raw:
        if key not in TOP_LEVEL_KEYS:
            raise ConfigError(f"unknown top-level key{closest(key, TOP_LEVEL_KEYS)}; known: "
                              f"{list(TOP_LEVEL_KEYS)}", file=file, key=str(key))
    resolved = resolve_placeholders(raw, args, env, file=file)
    config = ConfigFile(path=file, text=text, resolved=resolved)
    config.setup = _mapping(resolved.get("setup"), file, "setup")
    for key in config.setup:
        if key not in ("pip",):
            raise ConfigError(f"unknown setup key{closest(key, ['pip'])}; known: ['pip']", file=file,
                              key=f"setup.{key}")
    _check_pip(config.setup.get("pip", []), file)
    global_section = _mapping(resolved.get("global"), file, "global")
    for key in global_section:
        if key != "all":
            raise ConfigError("only 'global.all' is supported", file=file, key=f"global.{key}")
    config.global_all = _mapping(global_section.get("all"), file, "global.all")
    entries = resolved.get("modules")
    if not isinstance(entries, list) or not entries:
        raise ConfigError("'modules' must be a non-empty list of {name: ..., config: {...}}", file=file,
                          key="modules")
    for index, entry in enumerate(entries):
        if not isinstance(entry, dict):
            raise ConfigError(f"modules[{index}] must be a mapping with 'name' and 'config'", file=file,
                              key=f"modules[{index}]")
        name = entry.get("name")
        extra = [k for k in entry if k not in ("name", "config")]
        if extra:
            raise ConfigError(f"unknown key{closest(extra[0], ['name', 'config'])}; a module entry has 'name' "
                              "and 'config'", file=file, module=str(name), index=index, key=str(extra[0]))
        if not isinstance(name, str) or not name:
            raise ConfigError("every module needs a 'name'", file=file, index=index, key="name",
                              module=f"modules[{index}]")
        module_config = _mapping(entry.get("config"), file, "config", module=name, index=index)
        config.modules.append(ModuleEntry(name, module_config, index))
    return config


def _mapping(value: Any, file: str, key: str, *, module: str | None = None, index: int | None = None) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ConfigError(f"must be a mapping, got {type(value).__name__}", file=file, key=key, module=module,
                          index=index)
    return dict(value)


def _check_pip(packages: Any, file: str) -> None:
    """``setup.pip`` lists distributions the config needs: they are checked, never installed."""
    if not isinstance(packages, list) or not all(isinstance(p, str) for p in packages):
        raise ConfigError("must be a list of package names", file=file, key="setup.pip")
    missing = []
    for spec in packages:
        name = spec.split("[")[0].split("=")[0].split("<")[0].split(">")[0].split("~")[0].strip()
        try:
            metadata.version(name)
        except metadata.PackageNotFoundError:
            missing.append(spec)
    if missing:
        raise ConfigError(f"package(s) not installed: {', '.join(missing)}; install them with "
                          f"`.venv/bin/pip install {' '.join(missing)}` (hybridgen never installs packages)",
                          file=file, key="setup.pip")
