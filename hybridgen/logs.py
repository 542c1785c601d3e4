"""hybridgen's messages through the standard library's ``logging``, under the logger ``hybridgen``.

Library code reports one-line status messages through a ``log(message)`` callback (``RunContext.log``);
:func:`log_line` is the callback the command line passes: it gives each line its level. A line starting
with ``warning:`` is a warning (the prefix is dropped, the formatter adds it back); the lines that tell a
user their run did not start from scratch (:data:`RESUME_MARKERS`) are notices at warning level; everything
else is information. ``hybridgen -q`` shows warnings and errors only, ``-v`` adds debug lines.

Applications embedding hybridgen configure the ``hybridgen`` logger as they like; without configuration
Python shows warnings and errors on stderr.
"""
from __future__ import annotations

import logging
import sys
from typing import TextIO

LOGGER = logging.getLogger("hybridgen")

_WARNING_PREFIX = "warning: "
RESUME_MARKERS = ("resumed:", "nothing to do", "rendering it again")
"""Phrases of the runner's lines saying that a run did not start from scratch: notices, kept by ``-q``."""


def log_line(message: str) -> None:
    """Log one status line at the level it implies (see the module docstring)."""
    if message.startswith(_WARNING_PREFIX):
        LOGGER.warning(message[len(_WARNING_PREFIX):])
    elif any(marker in message for marker in RESUME_MARKERS):
        LOGGER.warning(f"notice: {message}")
    else:
        LOGGER.info(message)


class _LineFormatter(logging.Formatter):
    """``hybridgen: <message>``, with ``warning:`` / ``error:`` for those levels (notices keep their word)."""

    def format(self, record: logging.LogRecord) -> str:
        message = record.getMessage()
        if record.levelno >= logging.ERROR:
            message = f"error: {message}"
        elif record.levelno >= logging.WARNING and not message.startswith("notice:"):
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
