"""hybridgen's messages through the standard library's ``logging``, under the logger ``hybridgen``.

Library code reports one-line status messages through a ``log(message, level="info")`` callback
(``RunContext.log``, :class:`Log`); the caller names the level, nothing is guessed from the text:

- ``"info"``: what happened (``-q`` hides it);
- ``"notice"``: the run did not start from scratch (resumed, nothing to do, a file rendered again) - logged
  at warning level, shown as ``notice:`` and kept by ``-q``;
- ``"warning"``: something the user should look at.

:func:`log_line` is the callback the command line passes. ``hybridgen -q`` shows warnings and errors only,
``-v`` adds debug lines. Pool worker processes log like their parent (:func:`logging_setup` is handed to
:func:`configure` in each worker).

Applications embedding hybridgen configure the ``hybridgen`` logger as they like; without configuration
Python shows warnings and errors on stderr.
"""
from __future__ import annotations

import logging
import sys
from typing import Literal, Protocol, TextIO

LOGGER = logging.getLogger("hybridgen")

Level = Literal["debug", "info", "notice", "warning"]
LEVELS: dict[str, int] = {"debug": logging.DEBUG, "info": logging.INFO, "notice": logging.WARNING,
                          "warning": logging.WARNING}
"""A status line's level -> the ``logging`` level it is logged at (see the module documentation)."""

NOTICE_ATTR = "hybridgen_notice"
"""Set (True) on the log records of notices: warning-level records shown as ``notice:``."""


class Log(Protocol):
    """A status-line callback: ``log(message)`` for information, ``log(message, "warning")`` etc."""

    def __call__(self, message: str, level: Level = "info") -> None: ...


def log_line(message: str, level: Level = "info") -> None:
    """Log one status line at ``level`` (see the module documentation)."""
    if level not in LEVELS:
        raise ValueError(f"log level must be one of {list(LEVELS)}, got {level!r}")
    LOGGER.log(LEVELS[level], message, extra={NOTICE_ATTR: level == "notice"})


def no_log(message: str, level: Level = "info") -> None:
    """A :class:`Log` that drops every line (the default of library calls)."""


class _LineFormatter(logging.Formatter):
    """``hybridgen: <message>``, with ``notice:``, ``warning:``, ``error:`` or ``debug:`` for those levels."""

    def format(self, record: logging.LogRecord) -> str:
        message = record.getMessage()
        if record.levelno >= logging.ERROR:
            message = f"error: {message}"
        elif getattr(record, NOTICE_ATTR, False):
            message = f"notice: {message}"
        elif record.levelno >= logging.WARNING:
            message = f"warning: {message}"
        elif record.levelno < logging.INFO:
            message = f"debug: {message}"
        text = f"hybridgen: {message}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


class _StderrHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """Writes to whatever ``sys.stderr`` is at the time of each record (tests replace it)."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)

    @property  # type: ignore[override]
    def stream(self) -> TextIO:
        return sys.stderr

    @stream.setter
    def stream(self, value: TextIO) -> None:  # StreamHandler assigns it once; always follow sys.stderr
        pass


def level_for(verbose: int, quiet: bool) -> int:
    """The logging level for ``-v`` (repeatable) and ``-q``: quiet keeps warnings and errors."""
    if quiet:
        return logging.WARNING
    return logging.DEBUG if verbose > 0 else logging.INFO


def configure(level: int) -> None:
    """Send the ``hybridgen`` logger's records at ``level`` and above to stderr, one line each (idempotent)."""
    for handler in [h for h in LOGGER.handlers if isinstance(h, _StderrHandler)]:
        LOGGER.removeHandler(handler)
    handler = _StderrHandler()
    handler.setFormatter(_LineFormatter())
    LOGGER.addHandler(handler)
    LOGGER.setLevel(level)
    LOGGER.propagate = False


def logging_setup() -> int | None:
    """The level :func:`configure` gave this process's ``hybridgen`` logger, or None when it was not
    configured (an application's own setup): handed to worker processes so that they log like this one."""
    if any(isinstance(h, _StderrHandler) for h in LOGGER.handlers):
        return LOGGER.level
    return None
