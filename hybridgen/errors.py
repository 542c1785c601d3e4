"""Error types that the CLI turns into one line and exit status 2, and the "did you mean" of their messages."""
from __future__ import annotations

import difflib
import os
from typing import Iterable


def printable(text: str) -> str:
    """``text`` with the bytes of a file name that is not UTF-8 (Python's surrogate escapes) shown as ``\\xNN``:
    the form messages and HDF5 string attributes give them (a strict UTF-8 stream or log file cannot take
    the escapes themselves; ``os.fsencode`` of the original string gives the bytes back)."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def closest(name: str, known: Iterable[str]) -> str:
    """' (did you mean ...?)' with the closest known names, or '' when none is close."""
    matches = difflib.get_close_matches(str(name), list(known), n=3, cutoff=0.6)
    return f" (did you mean {' or '.join(repr(m) for m in matches)}?)" if matches else ""


def reject_unknown_keys(mapping: Iterable[str], known: Iterable[str], where: str = "") -> None:
    """Raises :class:`ConfigError` at the first key of ``mapping`` not in ``known``: located at ``<where>.<key>``
    (or ``<key>`` when ``where`` is empty), with the closest known names and the list of known ones."""
    names = list(known)
    for key in mapping:
        if key not in names:
            raise ConfigError(f"unknown key{closest(key, names)}; known: {', '.join(map(str, names))}",
                              key=f"{where}.{key}" if where else str(key))


class HybridgenError(Exception):
    """Base of every error that is the user's input, not a bug: shown as one line, exit status 2."""


class ConfigError(HybridgenError):
    """A config problem, located by file, module and key.

    The message reads ``<file>: module '<module>' (#<index>), key '<key>': <what is wrong>``;
    parts that are unknown are left out.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        module: str | None = None,
        index: int | None = None,
        key: str | None = None,
    ) -> None:
        self.file, self.module, self.index, self.key, self.detail = file, module, index, key, message
        super().__init__(self._format())

    def _format(self) -> str:
        where: list[str] = []
        if self.module is not None:
            where.append(f"module '{self.module}'" + (f" (#{self.index})" if self.index is not None else ""))
        if self.key is not None:
            where.append(f"key '{self.key}'")
        prefix = f"{self.file}: " if self.file else ""
        return prefix + (", ".join(where) + ": " if where else "") + self.detail

    def located(self, *, file: str | None = None, module: str | None = None,
                index: int | None = None, key: str | None = None) -> "ConfigError":
        """Return this error with missing location parts filled in (existing parts win)."""
        return ConfigError(
            self.detail,
            file=self.file or file,
            module=self.module or module,
            index=self.index if self.index is not None else index,
            key=self.key or key,
        )


class InputError(HybridgenError):
    """Bad input data: a missing or corrupt mesh, NaN vertices, an absurd resolution."""


class SystemSetupError(HybridgenError):
    """The machine lacks something hybridgen needs (EGL, a GL driver); the message says how to fix it."""


ENVIRONMENT_ERRNOS = {28: "no space left on the device", 122: "disk quota exceeded",
                      27: "file too large (the file size limit, ulimit -f, or the file system's)",
                      36: "file name too long for the file system", 30: "read-only file system",
                      13: "permission denied", 5: "input/output error"}
"""errno -> the words of the one-line message of an environment fault (ENOSPC, EDQUOT, EFBIG, ENAMETOOLONG,
EROFS, EACCES, EIO): the machine's state, not a bug - shown as one line like an input error."""


def fault_errno(exc: BaseException) -> int | None:
    """The errno of an environment fault behind ``exc`` (:data:`ENVIRONMENT_ERRNOS`), else None: an OSError's
    own errno, or the ``errno = N`` that HDF5 writes into the text of h5py's OSError and RuntimeError (a failed
    flush or close is a RuntimeError without an errno)."""
    import re

    if not isinstance(exc, (OSError, RuntimeError)):
        return None
    number = exc.errno if isinstance(exc, OSError) else None
    if number is None:
        match = re.search(r"errno = (\d+)", str(exc))
        number = int(match.group(1)) if match else None
    return number if number in ENVIRONMENT_ERRNOS else None


def fault_message(exc: BaseException) -> str | None:
    """One line for an environment fault (:func:`fault_errno`) - its words and the file it met, as the
    exception names it - or None when ``exc`` is not one."""
    import re

    number = fault_errno(exc)
    if number is None:
        return None
    name = getattr(exc, "filename", None)
    if name is None:
        match = re.search(r"filename = '([^']*)'", str(exc))
        name = match.group(1) if match else None
    where = f" at '{os.fsdecode(name)}'" if name is not None else ""
    return f"{ENVIRONMENT_ERRNOS[number]}{where} ([Errno {number}])"
