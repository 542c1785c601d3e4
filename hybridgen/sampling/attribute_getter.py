"""``getter.Attribute``: values read off the selected objects (BlenderProc's attribute getter).

``entities`` selects objects (getter.Entity); ``get`` names what to read of each: ``location`` (m, world),
``rotation_euler`` (rad, Blender's XYZ Euler of the object's rotation), ``scale``, ``name``, ``category_id``,
``cp_<name>`` (a custom property, hybridgen's attribute ``<name>``; ``cp_category_id`` the category) or
``cf_bounding_box_means`` (the centre of the object's world bounding box - the mean of its 8 corners, m).
The result is the list of values in selection order; ``transform_by: sum|avg`` turns numbers or vectors into
one value; ``index`` picks one entry (after ``transform_by``, as BlenderProc does).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from .getters import parse_selector, selected_or_fail
from .sampler_table import DrawContext, register_sampler

_PLAIN = ("location", "rotation_euler", "scale", "name", "category_id")


def _check(p: dict[str, Any]) -> None:
    get = p.get("get")
    if not isinstance(get, str) or not (get in _PLAIN or get.startswith("cp_") or get == "cf_bounding_box_means"):
        raise ValueError(f"get must be one of {', '.join(_PLAIN)}, cp_<name> or cf_bounding_box_means, got {get!r}")
    if p.get("transform_by", "sum") not in ("sum", "avg"):
        raise ValueError(f"transform_by must be sum or avg, got {p['transform_by']!r}")


def object_value(obj: Any, get: str) -> Any:
    """What ``get`` names of one object (see the module doc)."""
    from scipy.spatial.transform import Rotation

    matrix = obj.local2world
    if get == "location":
        return matrix[:3, 3].tolist()
    if get == "scale":
        return np.linalg.norm(matrix[:3, :3], axis=0).tolist()
    if get == "rotation_euler":
        rotation = matrix[:3, :3] / np.linalg.norm(matrix[:3, :3], axis=0)
        return Rotation.from_matrix(rotation).as_euler("xyz").tolist()
    if get == "name":
        return obj.name
    if get in ("category_id", "cp_category_id"):
        value = obj.category_id
    elif get == "cf_bounding_box_means":
        points = obj.world_vertices()
        return ((points.min(axis=0) + points.max(axis=0)) / 2).tolist()
    else:
        value = obj.attributes.get(get[3:])
    if value is None:
        raise InputError(f"getter.Attribute: object '{obj.name}' has no {get!r}")
    return value


@register_sampler("getter.Attribute", "Attribute", validate=_check)
def attribute(ctx: DrawContext, entities: Any, get: str, transform_by: str | None = None,
              index: int | None = None) -> Any:
    """The ``get`` value of every object ``entities`` selects (optionally summed/averaged, or one by index)."""
    _check({"get": get, **({"transform_by": transform_by} if transform_by is not None else {})})
    values: Any = [object_value(o, get) for o in selected_or_fail(parse_selector(entities), ctx, "getter.Attribute")]
    if transform_by is not None:
        try:
            stacked = np.array([np.asarray(v, dtype=np.float64) for v in values])
        except (TypeError, ValueError):
            raise ValueError(f"transform_by {transform_by} needs numbers or vectors, got {values[:3]!r}") from None
        merged = stacked.sum(axis=0) if transform_by == "sum" else stacked.mean(axis=0)
        values = float(merged) if merged.ndim == 0 else merged.tolist()
    if index is not None:
        values = values[int(index)]
    return values
