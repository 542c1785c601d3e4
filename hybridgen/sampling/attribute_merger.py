"""``getter.AttributeMerger``: BlenderProc's combination of several drawn values (sum or average)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .sampler_table import DrawContext, register_sampler


def _check(p: dict[str, Any]) -> None:
    if p.get("transform_by", "sum") not in ("sum", "avg"):
        raise ValueError(f"transform_by must be sum or avg, got {p['transform_by']!r}")
    elements = p.get("elements")
    if not isinstance(elements, list) or not elements:
        raise ValueError("elements must be a non-empty list of values or samplers")


@register_sampler("getter.AttributeMerger", "AttributeMerger", validate=_check)
def attribute_merger(ctx: DrawContext, elements: Sequence[Any], transform_by: str = "sum") -> Any:
    """The element-wise sum (or average, ``transform_by: avg``) of ``elements``, each drawn afresh;
    numbers or equally long vectors (e.g. a getter.POI plus a sampler.Uniform3d offset)."""
    _check({"elements": list(elements), "transform_by": transform_by})
    try:
        values = np.array([np.asarray(e, dtype=np.float64) for e in elements])
    except ValueError:
        raise ValueError("elements must all be numbers or all vectors of one length") from None
    merged = values.sum(axis=0) if transform_by == "sum" else values.mean(axis=0)
    return float(merged) if merged.ndim == 0 else merged
