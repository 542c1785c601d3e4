"""Options declared once, beside their use: a frozen dataclass of a component's options (a writer's, ...)
whose fields carry their :class:`~hybridgen.config.schema.Param` (type, unit, doc, choices, check).

The YAML module lists :func:`option_params` in its ``params`` (validated there, with file, module and key in
the message) and builds the options with :func:`from_config`, which trusts them; Python callers build them
with :func:`checked_options`, which validates them with the same declarations. Each value is validated once
on each path.
"""
from __future__ import annotations

from dataclasses import Field, field, fields, replace
from typing import Any, Callable, Mapping, TypeVar

from ..errors import ConfigError, closest
from .schema import Param

T = TypeVar("T")


def option(default: Any, type: str, doc: str, *, unit: str = "", choices: tuple[Any, ...] = (),
           check: Callable[[Any], str | None] | None = None, key: str = "") -> Any:
    """A dataclass field declaring one option; ``key``: its name in configs when that differs from the field's
    (e.g. BlenderProc's ``append_to_existing_output`` for ``append``)."""
    return field(default=default, metadata={"param": Param(key, type, default, unit, doc, choices, check)})


def _param(item: Field) -> Param:
    declared: Param = item.metadata["param"]
    return replace(declared, name=declared.name or item.name)


def option_params(cls: type) -> tuple[Param, ...]:
    """The :class:`Param` of every option of ``cls``, under its config key."""
    return tuple(_param(item) for item in fields(cls))


def from_config(cls: type[T], config: Mapping[str, Any]) -> T:
    """``cls`` from a module's validated config (keys as :func:`option_params` names them); not checked again."""
    return cls(**{item.name: config[_param(item).name] for item in fields(cls)})  # type: ignore[call-arg]


def checked_options(cls: type[T], **given: Any) -> T:
    """``cls`` with the options ``given`` by field name (others at their defaults), each validated by its
    declaration: ConfigError naming the option otherwise."""
    params = {item.name: replace(_param(item), name=item.name) for item in fields(cls)}  # type: ignore[arg-type]
    for name, value in given.items():
        if name not in params:
            raise ConfigError(f"unknown option{closest(name, list(params))}; known: {', '.join(params)}", key=name)
        params[name].check_value(value)
    return cls(**given)
