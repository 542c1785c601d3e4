"""Input file paths named in a config: from the working directory, as BlenderProc resolves them, then from
the config file's folder (docs/conventions.md section 5).

A relative path that exists from the current working directory is used as given (BlenderProc's behaviour,
so configs written for it keep working). Otherwise the same path relative to the folder of the config file
is tried, so a config can name ``assets/chair.obj`` beside itself and run from anywhere. When neither
exists the error names both places tried. Absolute paths and ``~`` are used as given.

While a config runs, :func:`config_folder` records its folder for code that only sees a value (samplers,
material dictionaries); outside a config run (the Python API) paths are used exactly as given. This module
sits below the packages (config, sampling, io, render) that all read input paths; resolving a module's path
parameters is :func:`hybridgen.config.paths.resolve_module_paths`.
"""
from __future__ import annotations

import contextlib
import contextvars
import glob
import os
from pathlib import Path
from typing import Iterator

from .errors import ConfigError

_CONFIG_FOLDER: contextvars.ContextVar[Path | None] = contextvars.ContextVar("hybridgen_config_folder",
                                                                              default=None)


@contextlib.contextmanager
def config_folder(config_path: str | Path | None) -> Iterator[None]:
    """Within the block, relative input paths fall back to the folder of ``config_path``."""
    token = _CONFIG_FOLDER.set(None if config_path is None else Path(config_path).resolve().parent)
    try:
        yield
    finally:
        _CONFIG_FOLDER.reset(token)


def _folder(config_path: str | Path | None) -> Path | None:
    return Path(config_path).resolve().parent if config_path is not None else _CONFIG_FOLDER.get()


def resolve_input(value: str, key: str, config_path: str | Path | None = None, noun: str = "file") -> str:
    """The file or folder ``value`` names: as given if it exists from the working directory, else from the
    config's folder; a :class:`ConfigError` on ``key`` naming both places when it is in neither.

    ``config_path`` defaults to the config of the run in progress (:func:`config_folder`); with none,
    ``value`` is returned unchanged (the caller reports a missing file itself). ``noun`` starts the error.
    """
    expanded = os.path.expanduser(value)
    folder = _folder(config_path)
    if folder is None or os.path.isabs(expanded) or os.path.exists(expanded):
        return expanded
    beside_config = folder / expanded
    if beside_config.exists():
        return str(beside_config)
    raise ConfigError(f"{noun} not found: '{value}' (tried {Path.cwd() / expanded} from the working directory "
                      f"and {beside_config} from the config's folder)", key=key)


def locate_input(value: str, config_path: str | Path | None = None) -> str:
    """Like :func:`resolve_input`, but a file found in neither place is returned as given, for callers that
    report missing files later with their own context (textures: the object using them)."""
    try:
        return resolve_input(value, "", config_path)
    except ConfigError:
        return os.path.expanduser(value)


def glob_inputs(pattern: str, config_path: str | Path | None = None) -> list[str]:
    """Sorted files matching the glob ``pattern`` from the working directory or, when none matches there,
    from the config's folder (``**`` recursive); empty when neither has a match."""
    expanded = os.path.expanduser(pattern)
    matches = sorted(glob.glob(expanded, recursive=True))
    folder = _folder(config_path)
    if matches or folder is None or os.path.isabs(expanded):
        return matches
    return sorted(glob.glob(str(folder / expanded), recursive=True))


def describe_glob_miss(pattern: str, config_path: str | Path | None = None) -> str:
    """Where a glob that matched nothing was tried, for error messages."""
    folder = _folder(config_path)
    places = [str(Path.cwd() / pattern)] + ([str(folder / pattern)] if folder is not None else [])
    return f"no file matches '{pattern}' (tried {' and '.join(places)})"


def not_found(noun: str, value: str | Path) -> str:
    """``"<noun> not found: '<value>'"``, plus both places tried when a config run looked in its folder too."""
    text = f"{noun} not found: '{value}'"
    folder = _CONFIG_FOLDER.get()
    if folder is None or os.path.isabs(value):
        return text
    return (f"{text} (tried {Path.cwd() / value} from the working directory and {folder / value} from the "
            "config's folder)")


_NAME_LINKS: list[str] = []  # [folder] of this process's links, made on first use


def utf8_path(path: str | Path) -> str:
    """``path`` as a string for libraries that take file names as UTF-8 text (Mitsuba's ``filename``): the
    path itself when it is valid UTF-8, else a symlink to it with a UTF-8 name and the same suffix (the
    library picks the format by it) in a private folder of this process, removed at exit. Paths are bytes
    on Linux: a Latin-1 file name of an old archive arrives as Python's surrogate escapes."""
    text = os.fspath(path)
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        pass
    import atexit
    import hashlib
    import shutil
    import tempfile

    target = os.fsencode(os.path.abspath(text))
    if not _NAME_LINKS:
        _NAME_LINKS.append(tempfile.mkdtemp(prefix="hybridgen-names-"))
        atexit.register(shutil.rmtree, _NAME_LINKS[0], True)
    suffix = os.fsdecode(os.path.splitext(target)[1]).encode("utf-8", "replace").decode("utf-8")
    link = os.path.join(_NAME_LINKS[0], hashlib.sha256(target).hexdigest()[:16] + suffix)
    if not os.path.lexists(link):
        os.symlink(target, link)
    return link
