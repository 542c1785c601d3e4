"""What ``hybridgen modules`` prints: every module with its parameters (type, unit, default, choices,
sampleable) and every sampler with its parameters, as text and as JSON-ready records."""
from __future__ import annotations

import inspect
from typing import Any, Mapping

from .schema import Param


def _summary(doc: str | None) -> str:
    """The first paragraph of a docstring as one line (never cut mid-sentence), without RST markup."""
    paragraph = inspect.cleandoc(doc or "").split("\n\n")[0]
    return " ".join(paragraph.split()).replace("``", "`")  # reStructuredText literals as plain backticks


def describe_param(param: Param) -> str:
    """One line: ``name: type [unit] (sampleable), default ... - doc; one of: a, b``."""
    choices = f"; one of: {', '.join(str(c) for c in param.choices)}" if param.choices else ""
    return param.describe() + choices


def describe_modules(modules: Mapping[str, type]) -> str:
    """The text listing of ``modules`` (name -> class)."""
    lines: list[str] = []
    for name, cls in modules.items():
        lines.append(f"{name}: {_summary(cls.__doc__)}")
        lines.extend(f"    {describe_param(p)}" for p in cls.params)
        lines.append("")
    return "\n".join(lines)


def sampler_parameters(fn: Any) -> list[tuple[str, Any]]:
    """``(name, default or REQUIRED marker None-less)`` of a sampler function, without its draw context."""
    out = []
    for index, parameter in enumerate(inspect.signature(fn).parameters.values()):
        if index == 0:  # the DrawContext
            continue
        out.append((parameter.name, parameter.default))
    return out


def describe_samplers() -> str:
    """Every sampler and getter usable as ``{provider: NAME, ...}``, with aliases and parameters."""
    from ..sampling.registry import ALIASES, SAMPLERS
    lines = ["samplers (any value marked sampleable may be {provider: NAME, parameter: value, ...}):"]
    for name, spec in sorted(SAMPLERS.items()):
        aliases = sorted(a for a, target in ALIASES.items() if target == name)
        also = f" (also {', '.join(aliases)})" if aliases else ""
        lines.append(f"{name}{also}: {_summary(spec.doc)}")
        for param, default in sampler_parameters(spec.fn):
            text = "required" if default is inspect.Parameter.empty else f"default {default!r}"
            lines.append(f"    {param}: {text}")
    return "\n".join(lines)


def describe_aliases() -> str:
    """BlenderProc module names: the hybridgen module each one runs as, and those hybridgen cannot provide."""
    from .blenderproc import ALIASES, UNAVAILABLE, unavailable_reason

    lines = ["BlenderProc module names (read with BlenderProc's keys in configs of BlenderProc's form):"]
    lines += [f"    {alias} -> {target}" for alias, target in sorted(ALIASES.items())]
    lines.append("not available (each fails with this reason):")
    lines += [f"    {name}: {why}" for name in sorted(UNAVAILABLE) if (why := unavailable_reason(name))]
    return "\n".join(lines)


def module_records(modules: Mapping[str, type]) -> list[dict[str, Any]]:
    """JSON-ready description of ``modules`` (for ``hybridgen modules --json``)."""
    records = []
    for name, cls in modules.items():
        params = [{"name": p.name, "type": p.type, "unit": p.unit, "required": p.required,
                   "default": None if p.required else _plain(p.default), "choices": [_plain(c) for c in p.choices],
                   "sampleable": p.sampleable, "doc": p.doc} for p in cls.params]
        records.append({"name": name, "doc": _summary(cls.__doc__), "parameters": params})
    return records


def _plain(value: Any) -> Any:
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value if value is None or isinstance(value, (bool, int, float, str)) else str(value)
