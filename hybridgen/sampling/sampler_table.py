"""The table of samplers and providers by name, filled by :func:`register_sampler` (the built-ins register
when :mod:`hybridgen.sampling.registry` imports them)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np


@dataclass
class DrawContext:
    """What a sampler may use: the run's generator and, for object-relative samplers, the scene."""

    rng: np.random.Generator
    scene: Any = None


SamplerFn = Callable[..., Any]


@dataclass(frozen=True)
class SamplerSpec:
    """A registered sampler: its function ``fn(ctx, **params)`` and a validator run at config load."""

    name: str
    fn: SamplerFn
    validate: Callable[[dict[str, Any]], None]
    doc: str


SAMPLERS: dict[str, SamplerSpec] = {}
ALIASES: dict[str, str] = {}


def register_sampler(name: str, *aliases: str, validate: Callable[[dict[str, Any]], None] | None = None
                     ) -> Callable[[SamplerFn], SamplerFn]:
    """Register ``fn(ctx: DrawContext, **params)`` as ``name`` (e.g. ``sampler.Uniform3d``) and aliases
    (e.g. the paper's ``Uniform3dSampler``)."""

    def decorate(fn: SamplerFn) -> SamplerFn:
        SAMPLERS[name] = SamplerSpec(name, fn, validate or (lambda params: None), (fn.__doc__ or "").strip())
        for alias in aliases:
            ALIASES[alias] = name
        return fn

    return decorate
