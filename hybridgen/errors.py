"""Error types that the CLI turns into one line and exit status 2, and the "did you mean" of their messages."""
from __future__ import annotations

import difflib
from typing import Iterable


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
