"""Selecting objects (BlenderProc's ``getter.Entity``) and object-relative providers (``getter.POI``,
``sampler.UpperRegionSampler``).

A selector is ``{conditions: C, random_samples: k}`` (optionally with ``provider: getter.Entity``) or the
conditions alone. Conditions: a mapping is an AND of its keys, a list an OR of mappings. Keys: ``name``
(regular expression, full match), ``category_id``, ``instance_id``, or any custom attribute (a
``cp_`` prefix, BlenderProc's custom-property spelling, is accepted); string values of attributes match
as regular expressions, others by equality.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import ConfigError, InputError
from .sampler_table import DrawContext, register_sampler

SELECTOR_KEYS = ("provider", "conditions", "random_samples", "index", "check_empty")


@dataclass(frozen=True)
class Selector:
    """Which objects a module acts on."""

    conditions: Any = None  # dict (AND), list of dicts (OR) or None (every object)
    random_samples: int | None = None
    index: int | None = None
    check_empty: bool = True  # BlenderProc's key (its default is false): an empty selection is an error

    def select(self, objects: Sequence[Any], rng: np.random.Generator | None = None) -> list[Any]:
        """The matching objects in scene order; ``random_samples`` of them drawn without replacement."""
        chosen = [o for o in objects if _matches(o, self.conditions)]
        if self.index is not None:
            chosen = chosen[self.index:self.index + 1] if -len(chosen) <= self.index < len(chosen) else []
        if self.random_samples is not None and len(chosen) > self.random_samples:
            if rng is None:
                raise ValueError("random_samples needs a random generator")
            picks = np.sort(rng.choice(len(chosen), size=self.random_samples, replace=False))
            chosen = [chosen[i] for i in picks]
        return chosen


def _attribute(obj: Any, key: str) -> Any:
    if key == "name":
        return obj.name
    if key in ("category_id", "instance_id", "cp_category_id"):  # BlenderProc's custom property is the category
        return getattr(obj, key.removeprefix("cp_"))
    if key == "material_name":  # BlenderProc's getter.Material selects by material name
        return obj.material.name
    name = key[3:] if key.startswith("cp_") else key
    return obj.attributes.get(name, _MISSING)


_MISSING = object()


def _matches(obj: Any, conditions: Any) -> bool:
    if conditions is None:
        return True
    if isinstance(conditions, list):
        return any(_matches(obj, c) for c in conditions)
    for key, wanted in conditions.items():
        actual = _attribute(obj, key)
        if actual is _MISSING:
            return False
        if isinstance(wanted, str) and isinstance(actual, str):
            if re.fullmatch(wanted, actual) is None:
                return False
        elif actual != wanted:
            return False
    return True


def parse_selector(value: Any, key: str = "selector") -> Selector:
    """A :class:`Selector` from its config form; ConfigError names ``key`` when malformed."""
    if value is None:
        return Selector()
    check_empty = True
    if isinstance(value, list):
        conditions: Any = value
        random_samples = index = None
    elif isinstance(value, dict):
        if not any(k in value for k in SELECTOR_KEYS):
            value = {"conditions": value}
        extra = [k for k in value if k not in SELECTOR_KEYS]
        if extra:
            raise ConfigError(f"unknown selector key(s) {extra}; a selector has {list(SELECTOR_KEYS)}", key=key)
        if value.get("provider", "getter.Entity") != "getter.Entity":
            raise ConfigError(f"a selector's provider is getter.Entity, got {value['provider']!r}", key=key)
        conditions, random_samples, index = value.get("conditions"), value.get("random_samples"), value.get("index")
        check_empty = value.get("check_empty", True)
        if not isinstance(check_empty, bool):
            raise ConfigError(f"check_empty must be true or false, got {check_empty!r}", key=key)
    else:
        raise ConfigError(f"a selector is a mapping of conditions or {{conditions, random_samples}}, got {value!r}",
                          key=key)
    items = conditions if isinstance(conditions, list) else [conditions] if conditions is not None else []
    for item in items:
        if not isinstance(item, dict):
            raise ConfigError(f"conditions must be mappings (AND) or lists of them (OR), got {item!r}", key=key)
        for name, wanted in item.items():
            if isinstance(wanted, str):
                try:
                    re.compile(wanted)
                except re.error as exc:
                    raise ConfigError(f"condition {name}: bad regular expression {wanted!r}: {exc}", key=key) from None
    if random_samples is not None and (not isinstance(random_samples, int) or random_samples < 1):
        raise ConfigError(f"random_samples must be an integer >= 1, got {random_samples!r}", key=key)
    return Selector(conditions, random_samples, index, check_empty)


def selected_or_fail(selector: Selector, ctx: DrawContext, what: str) -> list[Any]:
    """The selected objects of ``ctx.scene``; an InputError naming ``what`` when none matches."""
    chosen = selector.select(ctx.scene.objects, ctx.rng)
    if not chosen:
        raise InputError(f"{what}: no object matches {selector.conditions!r}")
    return chosen


def _world_box(obj: Any) -> np.ndarray:
    points = obj.world_vertices()
    return np.stack([points.min(axis=0), points.max(axis=0)])


@register_sampler("getter.POI", "POI")
def point_of_interest(ctx: DrawContext, selector: Any = None) -> np.ndarray:
    """BlenderProc's point of interest: of the selected objects' bounding-box centres, the one closest to
    their mean (m, world)."""
    chosen = selected_or_fail(parse_selector(selector), ctx, "getter.POI")
    centres = np.array([_world_box(o).mean(axis=0) for o in chosen])
    return centres[np.argmin(np.linalg.norm(centres - centres.mean(axis=0), axis=1))]


def _check_upper(p: dict[str, Any]) -> None:
    if "min_height" in p and "max_height" in p and p["min_height"] > p["max_height"]:
        raise ValueError(f"min_height {p['min_height']} > max_height {p['max_height']}")
    if "face_sample_range" in p:
        low, high = p["face_sample_range"]
        if not 0 <= low <= high <= 1:
            raise ValueError(f"face_sample_range must satisfy 0 <= low <= high <= 1, got {p['face_sample_range']}")


@register_sampler("sampler.UpperRegionSampler", "UpperRegionSampler", validate=_check_upper)
def upper_region(ctx: DrawContext, to_sample_on: Any, min_height: float = 0.0, max_height: float = 1.0,
                 face_sample_range: Sequence[float] = (0.0, 1.0)) -> np.ndarray:
    """A point above the top face of the world bounding box of one of the selected objects: x, y within
    ``face_sample_range`` (fractions of the face), z between ``min_height`` and ``max_height`` above it (m)."""
    _check_upper(dict(min_height=min_height, max_height=max_height, face_sample_range=face_sample_range))
    chosen = selected_or_fail(parse_selector(to_sample_on), ctx, "UpperRegionSampler")
    box = _world_box(chosen[int(ctx.rng.integers(len(chosen)))])
    low, high = face_sample_range
    fx, fy = ctx.rng.uniform(low, high, size=2)
    x = box[0, 0] + fx * (box[1, 0] - box[0, 0])
    y = box[0, 1] + fy * (box[1, 1] - box[0, 1])
    return np.array([x, y, box[1, 2] + ctx.rng.uniform(min_height, max_height)])
