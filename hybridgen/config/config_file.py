"""Reading a config file in the paper's shape: ``setup`` / ``global`` / ``modules`` (docs/conventions.md section 5)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import yaml

from ..errors import ConfigError, closest
from .blenderproc import BLENDER_PYTHON_PACKAGES, BLENDER_SETUP_KEYS, FAMILY_READ, GLOBAL_IGNORED
from .blenderproc import finish as finish_translation
from .blenderproc import translate_module
from .notices import notice
from .placeholders import resolve_placeholders
from .requirements import NOT_A_REQUIREMENT, RequirementCheck, check_requirements
from .roles import Role
from .yaml_safety import MAX_CONFIG_BYTES, load_yaml, read_limited

TOP_LEVEL_KEYS = ("setup", "global", "modules", "version")
SUPPORTED_VERSIONS = (1, 2, 3)
"""BlenderProc 1.x config format versions (v1.0 configs have none; v1.12 write ``version: 3``)."""


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
        return yaml.constructor.SafeConstructor.construct_mapping(self, node, deep=deep)


class _FastStrictLoader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """:class:`_StrictLoader` with libyaml's parser (PyYAML's C extension, when built with it): the same Python
    constructor and resolver, ~8x less CPU for a config listing 120 camera poses (95 -> 12 ms)."""

    construct_mapping = _StrictLoader.construct_mapping


def _parse(text: str, file: str) -> Any:
    """The config's YAML through libyaml's parser; any error is raised by PyYAML's own parser instead, so that
    messages and marks are PyYAML's."""
    try:
        return load_yaml(text, _FastStrictLoader, file)
    except (yaml.YAMLError, ConfigError):
        return load_yaml(text, _StrictLoader, file)


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
    """Parse ``path``, check its shape, resolve placeholders and the ``setup.pip`` requirements.

    BlenderProc 1.x configs are read as they are (see :mod:`hybridgen.config.blenderproc`): ``module:`` or
    ``name:``, ``version``, the Initializer's ``config.global`` (v3) or a top-level ``global`` (v1), Blender
    ``setup`` keys (ignored with one notice, their placeholders never resolved), BlenderProc module names
    and keys. Every difference is one notice line (an error with ``--strict``).
    """
    file = str(path)
    try:
        text = read_limited(path, MAX_CONFIG_BYTES, "config file").decode("utf-8")
    except FileNotFoundError:
        raise ConfigError("config file not found", file=file) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read config file: {exc}", file=file) from None
    try:
        raw = _parse(text, file)  # bounded depth and alias expansion (yaml_safety)
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
    version = raw.get("version")
    if version is not None and (not isinstance(version, int) or isinstance(version, bool) or
                                version not in SUPPORTED_VERSIONS):
        raise ConfigError(f"config format version {version!r} is not one of {list(SUPPORTED_VERSIONS)} "
                          "(BlenderProc 1.x)", file=file, key="version")
    # Blender's own setup keys are set aside before placeholders are resolved: an <env:USER> in
    # blender_install_path must not stop a run that never uses it.
    raw_setup = _mapping(raw.get("setup"), file, "setup")
    blender_setup = {k: raw_setup[k] for k in raw_setup if k in BLENDER_SETUP_KEYS}
    to_resolve = dict(raw)
    if "setup" in raw:
        to_resolve["setup"] = {k: v for k, v in raw_setup.items() if k not in blender_setup}
    resolved = resolve_placeholders(to_resolve, args, env, file=file)
    config = ConfigFile(path=file, text=text, resolved=resolved)
    config.setup = _mapping(resolved.get("setup"), file, "setup")
    for key in config.setup:
        if key not in ("pip",):
            raise ConfigError(f"unknown setup key{closest(key, ['pip', *BLENDER_SETUP_KEYS])}; known: "
                              f"{['pip', *BLENDER_SETUP_KEYS]}", file=file, key=f"setup.{key}")
    if blender_setup:
        notice(f"ignored: {', '.join(blender_setup)} locate Blender; hybridgen renders without Blender",
               file=file, key="setup")
    _check_pip(config.setup.get("pip", []), file)
    entries = resolved.get("modules")
    if not isinstance(entries, list) or not entries:
        raise ConfigError("'modules' must be a non-empty list of {module: ..., config: {...}}", file=file,
                          key="modules")
    blenderproc_form = version is not None or bool(blender_setup) or any(
        isinstance(e, dict) and "module" in e for e in entries)
    global_section = _mapping(resolved.get("global"), file, "global")
    family_globals: dict[str, dict[str, Any]] = {}
    family_read = FAMILY_READ if blenderproc_form else {}
    for key in global_section:
        if key != "all":
            if "." in str(key) or not isinstance(global_section[key], dict):
                raise ConfigError("'global' holds 'all' and module families (e.g. 'renderer') with their "
                                  "settings", file=file, key=f"global.{key}")
            family_globals[str(key)] = {}
            for name, value in global_section[key].items():
                if name in GLOBAL_IGNORED and name not in family_read.get(str(key), ()):
                    notice(f"ignored: {GLOBAL_IGNORED[name]}", file=file, key=f"global.{key}.{name}")
                else:
                    family_globals[str(key)][name] = value
    config.global_all = _mapping(global_section.get("all"), file, "global.all")
    state: dict[str, Any] = {"blenderproc": blenderproc_form, "version": version}
    for index, entry in enumerate(entries):
        name, module_config = _module_entry(entry, index, file)
        family = family_globals.get(name.split(".", 1)[0])
        if family:  # BlenderProc v1: global.<family> settings are defaults for that family's modules
            module_config = {**family, **module_config}
        if "global" in module_config and _sets_up_run(name):  # BlenderProc v3: the Initializer holds 'global'
            module_config = dict(module_config)
            initializer_global = _mapping(module_config.pop("global"), file, "config.global", module=name,
                                          index=index)
            config.global_all = {**config.global_all, **initializer_global}

        def note(message: str, key: str, name: str = name, index: int = index) -> None:
            notice(message, file=file, module=name, index=index, key=key)

        try:
            translated = translate_module(name, module_config, note, state)
        except ConfigError as exc:
            raise exc.located(file=file, module=name, index=index) from None
        for target, target_config in translated:
            config.modules.append(ModuleEntry(target, target_config, index))
    finish_translation(config.modules, state, config.global_all.get("output_dir"))
    if blenderproc_form:
        _keep_renderer_outputs(config.modules, file)
    if blenderproc_form and "output_dir" in config.global_all and not _declared(config.modules, "output_dir"):
        del config.global_all["output_dir"]  # BlenderProc always sets it (also for its temporary files)
    for key in [k for k in config.global_all if k in GLOBAL_IGNORED]:
        notice(f"ignored: {GLOBAL_IGNORED[key]}", file=file, key=f"global.{key}")
        del config.global_all[key]
    return config


def _keep_renderer_outputs(modules: list[ModuleEntry], file: str) -> None:
    """A BlenderProc config that renders without a writer keeps the renderers' own files in BlenderProc
    (``rgb_0000.png`` ... with ``output_is_temp: false``): hybridgen writes what they render into
    ``data.hdf5`` instead (a writer.Hdf5Writer after the last renderer, and a notice)."""
    renderers = [m for m in modules if m.name.startswith("renderer.")]
    if not renderers or any(m.name.startswith("writer.") for m in modules):
        return
    last = renderers[-1]
    notice("the config renders but has no writer: BlenderProc keeps the renderers' own image files here; "
           "hybridgen writes them into <output_dir>/data.hdf5 (`hybridgen extract` makes image files of it)",
           file=file, module=last.name, index=last.index)
    modules.insert(modules.index(last) + 1, ModuleEntry("writer.Hdf5Writer", {}, last.index))


def _sets_up_run(name: str) -> bool:
    """True if ``name`` is a setup module (run-wide settings, e.g. main.Initializer); unknown names are not."""
    from .registry import get_module

    try:
        return get_module(name).role is Role.SETUP
    except ConfigError:
        return False


def _declared(modules: list[ModuleEntry], key: str) -> bool:
    """True if some module of the list declares the parameter ``key`` (unknown modules count as not)."""
    from .registry import get_module

    for entry in modules:
        try:
            if key in get_module(entry.name).param_table():
                return True
        except ConfigError:
            continue
    return False


def _module_entry(entry: Any, index: int, file: str) -> tuple[str, dict[str, Any]]:
    """``(name, config)`` of one ``modules`` item, written with ``module:`` (BlenderProc v3) or ``name:``."""
    if not isinstance(entry, dict):
        raise ConfigError(f"modules[{index}] must be a mapping with 'module' (or 'name') and 'config'", file=file,
                          key=f"modules[{index}]")
    if "module" in entry and "name" in entry and entry["module"] != entry["name"]:
        raise ConfigError(f"'module' ({entry['module']!r}) and 'name' ({entry['name']!r}) differ; give one",
                          file=file, index=index, key="module", module=f"modules[{index}]")
    name = entry.get("module", entry.get("name"))
    extra = [k for k in entry if k not in ("module", "name", "config")]
    if extra:
        raise ConfigError(f"unknown key{closest(extra[0], ['module', 'name', 'config'])}; a module entry has "
                          "'module' (or 'name') and 'config'", file=file, module=str(name), index=index,
                          key=str(extra[0]))
    if not isinstance(name, str) or not name:
        raise ConfigError("every module needs a 'name' (or BlenderProc's 'module')", file=file, index=index, key="name",
                          module=f"modules[{index}]")
    return name, _mapping(entry.get("config"), file, "config", module=name, index=index)


def _mapping(value: Any, file: str, key: str, *, module: str | None = None, index: int | None = None) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ConfigError(f"must be a mapping, got {type(value).__name__}", file=file, key=key, module=module,
                          index=index)
    return dict(value)


def _check_pip(packages: Any, file: str) -> None:
    """``setup.pip`` lists distributions the config needs: they are checked, never installed.

    Packages BlenderProc configs install into Blender's Python (h5py, pypng, scikit-image ...) and entries
    that are not plain requirements (URLs, ``-f`` options) are a notice when missing; any other missing
    package (a plugin's) is an error.
    """
    if not isinstance(packages, list) or not all(isinstance(p, str) for p in packages):
        raise ConfigError("must be a list of package names", file=file, key="setup.pip")
    missing: list[RequirementCheck] = []
    blender_only: list[str] = []
    for check in check_requirements(packages):  # PEP 508 specifiers against what is installed (packaging)
        if check.met:
            continue
        if check.status == NOT_A_REQUIREMENT or check.name in BLENDER_PYTHON_PACKAGES or \
                check.name.replace("-", "_") in BLENDER_PYTHON_PACKAGES:
            blender_only.append(check.describe())
        else:
            missing.append(check)
    if blender_only:
        notice(f"not installed as asked, and not needed by hybridgen's modules (BlenderProc installs them into "
               f"Blender's Python): {', '.join(blender_only)}", file=file, key="setup.pip")
    if missing:
        raise ConfigError(f"requirement(s) not met: {', '.join(m.describe() for m in missing)}; install them with "
                          f"`.venv/bin/pip install {' '.join(repr(m.spec) for m in missing)}` "
                          "(hybridgen never installs packages)", file=file, key="setup.pip")
