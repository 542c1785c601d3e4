"""Registry of samplers and providers by name, and the lazy ``Sampled`` values configs turn into.

A config value ``{provider: sampler.Uniform3d, min: [...], max: [...]}`` or, in the paper's form,
``{name: Uniform3dSampler, parameters: {min: [...], max: [...]}}`` becomes a :class:`Sampled`; a module
draws it with :func:`draw` each time it reads it, so every object / pose / light gets a fresh value.
Parameters are validated when the config is loaded (``min > max`` is an error then, not at the 500th draw).
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..nested import map_nested
from ..errors import ConfigError, InputError, closest
from . import attribute_getter, attribute_merger, getters, samplers  # noqa: F401  (they register)
from . import texture_getter, texture_sampler  # noqa: F401  (they register)
from .sampler_table import ALIASES, SAMPLERS, DrawContext, SamplerSpec


def _known() -> list[str]:
    return sorted([*SAMPLERS, *ALIASES])


@dataclass
class Sampled:
    """A config value drawn afresh every time a module reads it."""

    spec: SamplerSpec
    params: dict[str, Any]

    def draw(self, ctx: DrawContext) -> Any:
        params = {k: draw(v, ctx) for k, v in self.params.items()}
        try:
            return self.spec.fn(ctx, **params)
        except (ValueError, TypeError) as exc:
            raise InputError(f"{self.spec.name}: {exc}") from None


def is_sampler_dict(value: Any) -> bool:
    """True for ``{provider: ...}`` and the paper's ``{name: ..., parameters: {...}}`` (selectors, whose
    provider is ``getter.Entity``, are not values)."""
    if not isinstance(value, dict) or value.get("provider") == "getter.Entity":
        return False
    return "provider" in value or ("name" in value and "parameters" in value)


def parse_sampled(value: dict[str, Any], key: str = "") -> Sampled:
    """Turn a sampler dict into a :class:`Sampled`, validating name and parameters."""
    if "provider" in value:
        name = value["provider"]
        params = {k: v for k, v in value.items() if k != "provider"}
    else:
        name = value["name"]
        extra = [k for k in value if k not in ("name", "parameters")]
        if extra:
            raise ConfigError(f"a sampler in the paper's form has only 'name' and 'parameters', got {extra}", key=key)
        params = dict(value["parameters"] or {})
    name = ALIASES.get(name, name)
    if name not in SAMPLERS:
        raise ConfigError(f"unknown sampler {value.get('provider', value.get('name'))!r}"
                          f"{closest(str(name), _known())}; known: {', '.join(sorted(SAMPLERS))}", key=key)
    spec = SAMPLERS[name]
    params = {k: parse_value(v, f"{key}.{k}") for k, v in params.items()}
    signature = inspect.signature(spec.fn)
    accepted = [p for p in signature.parameters if p != "ctx"]
    for param in params:
        if param not in accepted:
            raise ConfigError(f"{name} has no parameter {param!r}{closest(param, accepted)}; it takes "
                              f"{', '.join(accepted)}", key=key)
    missing = [p.name for p in signature.parameters.values()
               if p.name != "ctx" and p.default is inspect.Parameter.empty and p.name not in params]
    if missing:
        raise ConfigError(f"{name} needs {', '.join(missing)}", key=key)
    constant = {k: v for k, v in params.items() if not isinstance(v, Sampled)}
    try:
        spec.validate(constant)
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{name}: {exc}", key=key) from None
    return Sampled(spec, params)


def parse_value(value: Any, key: str = "") -> Any:
    """A config value with every sampler dict inside it (at any depth) turned into a :class:`Sampled`."""
    return map_nested(value, lambda item, where: parse_sampled(item, where) if is_sampler_dict(item) else item, key,
                      is_sampler_dict)


def contains_sampled(value: Any) -> bool:
    """True if a :class:`Sampled` is anywhere inside ``value``."""
    if isinstance(value, Sampled):
        return True
    if isinstance(value, dict):
        return any(contains_sampled(v) for v in value.values())
    if isinstance(value, list):
        return any(contains_sampled(v) for v in value)
    return False


def draw(value: Any, ctx: DrawContext) -> Any:
    """``value`` with every :class:`Sampled` inside it drawn once, in order (numpy results become
    lists/scalars)."""
    return map_nested(value, lambda item, where: _plain(item.draw(ctx)) if isinstance(item, Sampled) else item)


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value
