"""One line for a BlenderProc call hybridgen does not implement: ``bproc.<area>.<name> is not supported by hybridgen
yet``. Never a silent no-op: such a call would change BlenderProc's output, so it stops the script (exit status 2
under ``hybridgen run``)."""
from __future__ import annotations

import importlib
from typing import Any, Callable, Iterable, Mapping, NoReturn

from ...errors import InputError


class UnsupportedError(InputError):
    """A BlenderProc call with no hybridgen counterpart yet (an :class:`~hybridgen.errors.InputError`)."""


def fail(call: str, why: str = "") -> NoReturn:
    """Raise the one line for ``call`` (e.g. ``bproc.object.simulate_physics``)."""
    raise UnsupportedError(f"{call} is not supported by hybridgen yet" + (f" ({why})" if why else ""))


def unsupported_function(call: str, why: str = "") -> Callable[..., Any]:
    """A stand-in for the BlenderProc function ``call`` that raises :func:`fail` when called."""

    def stand_in(*_args: Any, **_kwargs: Any) -> NoReturn:
        fail(call, why)

    stand_in.__name__ = call.rpartition(".")[2]
    stand_in.__doc__ = f"{call}: not supported by hybridgen yet (raises one line)."
    return stand_in


def unsupported_method(class_name: str, name: str, why: str = "") -> Callable[..., Any]:
    """A method of ``bproc.types.<class_name>`` that raises one line naming it."""
    return unsupported_function(f"bproc.types.{class_name}.{name}", why)


def module_getattr(area: str, names: Iterable[str], lazy: Mapping[str, str] | None = None,
                   namespace: dict[str, Any] | None = None) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``bproc.<area>``: BlenderProc's ``names`` this module lacks become stand-ins
    that raise one line when called; a name in ``lazy`` is imported, on first use, from the ``hybridgen.bproc``
    module it maps to and kept in ``namespace`` (the module's globals), so that a script that never calls it does
    not pay for its imports at start; any other name is an AttributeError as usual."""
    known, deferred = frozenset(names), dict(lazy or {})

    def __getattr__(name: str) -> Any:  # noqa: N807 - a module's __getattr__
        if name in deferred:
            value = getattr(importlib.import_module(f"hybridgen.bproc.{deferred[name]}"), name)
            if namespace is not None:
                namespace[name] = value
            return value
        if name in known:
            return unsupported_function(f"bproc.{area}.{name}")
        raise AttributeError(f"module 'bproc.{area}' has no attribute {name!r}")

    return __getattr__
