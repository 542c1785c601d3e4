"""``<args:N>`` and ``<env:NAME>`` placeholders in config values (docs/conventions.md section 5).

A placeholder may be a whole value or part of a string (``"<args:0>/meshes"``). Every missing one is
reported at once, each with the config path where it is used.
"""
from __future__ import annotations

import os
import re
from typing import Any, Mapping, Sequence

from ..errors import ConfigError
from ..nested import map_nested

PLACEHOLDER = re.compile(r"<(args|env):([^<>]*)>")


def resolve_placeholders(value: Any, args: Sequence[str], env: Mapping[str, str] | None = None,
                         *, file: str | None = None) -> Any:
    """Return ``value`` with every placeholder substituted; raise one ConfigError listing all missing ones."""
    environ = os.environ if env is None else env
    missing: list[str] = []

    def substitute(text: str, where: str) -> str:
        def one(match: re.Match[str]) -> str:
            kind, ref = match.group(1), match.group(2)
            if kind == "args":
                if not ref.isdigit():
                    missing.append(f"{match.group(0)} at {where} (N must be a non-negative integer)")
                    return match.group(0)
                index = int(ref)
                if index >= len(args):
                    missing.append(f"{match.group(0)} at {where}")
                    return match.group(0)
                return str(args[index])
            if ref not in environ:
                missing.append(f"{match.group(0)} at {where}")
                return match.group(0)
            return environ[ref]

        return PLACEHOLDER.sub(one, text)

    resolved = map_nested(value, lambda item, where: substitute(item, where) if isinstance(item, str) else item)
    if missing:
        given = f"{len(args)} argument(s) given after the config path" + (f": {list(args)}" if args else "")
        raise ConfigError(f"missing placeholder value(s): {'; '.join(missing)} ({given})", file=file)
    return resolved
