"""Declared module parameters: one place for name, type, default, unit and doc; validation with suggestions."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

from ..errors import ConfigError, closest, reject_unknown_keys

REQUIRED = object()
"""Default marker of a parameter that has to be given."""

# Type names a Param may declare, with the check each stands for.
_TYPE_CHECKS: dict[str, Callable[[Any], bool]] = {
    "any": lambda v: True,
    "bool": lambda v: isinstance(v, bool),
    "int": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "float": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
    "str": lambda v: isinstance(v, str),
    "path": lambda v: isinstance(v, str) and v != "",
    "list": lambda v: isinstance(v, list),
    "dict": lambda v: isinstance(v, dict),
    "vec3": lambda v: isinstance(v, list) and len(v) == 3 and all(_TYPE_CHECKS["float"](x) for x in v),
    "null": lambda v: v is None,
}


@dataclass(frozen=True)
class Param:
    """One module parameter.

    ``type`` is a name from the table above or several joined by ``|`` (``"str|list"``);
    ``choices`` restricts values (each element, for lists); ``check`` returns an error text or None.
    ``sampleable`` values may be samplers (``{provider: ...}``), at any depth; they are checked against the
    type when drawn (:meth:`Module.value`).
    """

    name: str
    type: str
    default: Any = REQUIRED
    unit: str = ""
    doc: str = ""
    choices: tuple[Any, ...] = ()
    check: Callable[[Any], str | None] | None = field(default=None, compare=False)
    sampleable: bool = False

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def validate(self, value: Any) -> Any:
        """Return ``value`` if it fits, else raise ConfigError naming the key (module/file added by callers)."""
        if self.sampleable:
            from ..sampling.registry import Sampled, contains_sampled, parse_value

            value = parse_value(value, self.name)
            if isinstance(value, Sampled) or contains_sampled(value):
                return value
        return self.check_value(value)

    def check_value(self, value: Any) -> Any:
        """Type, choices and custom check of a concrete (drawn) value."""
        types = self.type.split("|")
        if not any(_TYPE_CHECKS[t](value) for t in types):
            raise ConfigError(f"expected {self.type.replace('|', ' or ')}, got {type(value).__name__} {value!r}",
                              key=self.name)
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f"must be finite, got {value!r}", key=self.name)
        if self.choices:
            items = value if isinstance(value, list) else [value]
            for item in items:
                if item not in self.choices:
                    raise ConfigError(f"{item!r} is not one of {list(self.choices)}{closest(item, self.choices)}",
                                      key=self.name)
        if self.check is not None:
            problem = self.check(value)
            if problem:
                raise ConfigError(problem, key=self.name)
        return value

    def describe(self) -> str:
        """One line for `hybridgen modules`."""
        default = "required" if self.required else f"default {self.default!r}"
        unit = f" [{self.unit}]" if self.unit else ""
        sampled = " (sampleable)" if self.sampleable else ""
        return f"{self.name}: {self.type}{unit}{sampled}, {default} - {self.doc}"


def validate_config(params: Mapping[str, Param], given: Mapping[str, Any],
                    inherited: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Validate ``given`` against ``params``; fill defaults and declared keys from ``inherited`` (global.all).

    Unknown keys in ``given`` are errors with a suggestion; ``inherited`` keys the module does not declare
    are ignored (they are meant for other modules).
    """
    out: dict[str, Any] = {}
    reject_unknown_keys(given, sorted(params))
    for name, param in params.items():
        if name in given:
            out[name] = param.validate(given[name])
        elif inherited is not None and name in inherited:
            out[name] = param.validate(inherited[name])
        elif param.required:
            raise ConfigError("required key is missing", key=name)
        else:
            out[name] = param.default
    return out


def positive(value: Any) -> str | None:
    """A ``check`` that requires a number > 0."""
    return None if value > 0 else f"must be > 0, got {value!r}"
