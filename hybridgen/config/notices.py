"""Notices: one line for each thing a config asks that hybridgen accepts but does differently.

A BlenderProc config may name Blender-only settings (``setup.blender_install_path``, Cycles options,
``setup.pip`` packages for Blender's Python). hybridgen accepts them and says once, on stderr, what it did
instead; nothing is dropped silently. In strict mode (``hybridgen run --strict``, or the environment
variable ``HYBRIDGEN_STRICT=1`` that it sets for worker processes) every notice is a
:class:`~hybridgen.errors.ConfigError` instead.
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from ..errors import ConfigError
from ..logs import log_line

STRICT_ENV = "HYBRIDGEN_STRICT"
_seen: set[str] = set()
_sink: Callable[[str], None] | None = None
_recorders: list[list[dict[str, Any]]] = []


def set_strict(strict: bool) -> None:
    """Turn strict mode on or off for this process and the worker processes it starts."""
    if strict:
        os.environ[STRICT_ENV] = "1"
    else:
        os.environ.pop(STRICT_ENV, None)


def is_strict() -> bool:
    """True when notices are errors."""
    return os.environ.get(STRICT_ENV, "") not in ("", "0")


def set_sink(sink: Callable[[str], None] | None) -> None:
    """Send notice lines to ``sink`` instead of stderr (None: stderr again); tests use it."""
    global _sink
    _sink = sink


def notice(message: str, *, file: str | None = None, module: str | None = None, index: int | None = None,
           key: str | None = None) -> None:
    """Report one difference: a line on stderr (once per process), or a ConfigError in strict mode."""
    for recorded in _recorders:
        recorded.append({"message": message, "file": file, "module": module, "index": index, "key": key})
    error = ConfigError(message, file=file, module=module, index=index, key=key)
    if is_strict():
        raise ConfigError(f"{message} (an error because of --strict)", file=file, module=module, index=index,
                          key=key)
    line = f"hybridgen: notice: {error}"
    if _sink is not None:
        _sink(line)
        return
    if line not in _seen:
        _seen.add(line)
        log_line(str(error), "notice")  # the CLI prints "hybridgen: notice: ..."


@contextmanager
def recording_notices() -> Iterator[list[dict[str, Any]]]:
    """Within the block, every notice is also recorded (as :func:`notice`'s arguments) in the list the block
    gets, before strict mode turns it into an error: work that is cached (a parsed mesh) keeps the notices it
    issued and gives them again, with :func:`notice`, when its result is read back."""
    recorded: list[dict[str, Any]] = []
    _recorders.append(recorded)
    try:
        yield recorded
    finally:
        _recorders.remove(recorded)
