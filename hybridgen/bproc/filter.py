"""``bproc.filter``: select entities or materials by attribute or custom property (BlenderProc's Filter).

Equality as BlenderProc tests it: numbers and arrays compare element-wise (broadcast; all must match), strings
exactly or, with ``regex=True``, by ``re.fullmatch``."""
from __future__ import annotations

import re
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from .types import Struct


def _equal(value: Any, wanted: Any, regex: bool) -> bool:
    if isinstance(value, str) and isinstance(wanted, str):
        return bool(re.fullmatch(wanted, value)) if regex else value == wanted
    try:
        return bool(np.all(np.asarray(value) == np.asarray(wanted)))
    except ValueError:
        raise InputError(f"cannot compare attribute value {value!r} with {wanted!r}") from None


def _typed(elements: Sequence[Struct], data_type: type | None) -> list[Struct]:
    return [e for e in elements if data_type is None or isinstance(e, data_type)]


def _one(found: list[Struct], what: str) -> Struct:
    if len(found) > 1:
        raise InputError(f"more than one element with {what} has been found")
    if not found:
        raise InputError(f"no element with {what} has been found")
    return found[0]


def all_with_type(elements: Sequence[Struct], filtered_data_type: type | None = None) -> list[Struct]:
    """The elements that are instances of ``filtered_data_type`` (all when None)."""
    return _typed(elements, filtered_data_type)


def by_attr(elements: Sequence[Struct], attr_name: str, value: Any, filtered_data_type: type | None = None,
            regex: bool = False) -> list[Struct]:
    """The elements whose attribute ``attr_name`` (``name``, ``location`` ...) equals ``value``."""
    return [e for e in _typed(elements, filtered_data_type) if _equal(e.get_attr(attr_name), value, regex)]


def one_by_attr(elements: Sequence[Struct], attr_name: str, value: Any, filtered_data_type: type | None = None,
                regex: bool = False) -> Struct:
    """The one element :func:`by_attr` finds (none or several is an error)."""
    return _one(by_attr(elements, attr_name, value, filtered_data_type, regex), f"{attr_name} = {value!r}")


def by_cp(elements: Sequence[Struct], cp_name: str, value: Any, filtered_data_type: type | None = None,
          regex: bool = False) -> list[Struct]:
    """The elements holding custom property ``cp_name`` equal to ``value``."""
    return [e for e in _typed(elements, filtered_data_type)
            if e.has_cp(cp_name) and _equal(e.get_cp(cp_name), value, regex)]


def one_by_cp(elements: Sequence[Struct], cp_name: str, value: Any, filtered_data_type: type | None = None,
              regex: bool = False) -> Struct:
    """The one element :func:`by_cp` finds."""
    return _one(by_cp(elements, cp_name, value, filtered_data_type, regex), f"custom property {cp_name} = {value!r}")


def _in_interval(value: Any, low: Any, high: Any) -> bool:
    array = np.asarray(value)
    return bool((low is None or np.all(array >= low)) and (high is None or np.all(array <= high)))


def by_attr_in_interval(elements: Sequence[Struct], attr_name: str, min_value: Any = None, max_value: Any = None,
                        filtered_data_type: type | None = None) -> list[Struct]:
    """The elements whose attribute lies within [min_value, max_value] (a missing bound is open)."""
    return [e for e in _typed(elements, filtered_data_type) if _in_interval(e.get_attr(attr_name), min_value, max_value)]


def by_attr_outside_interval(elements: Sequence[Struct], attr_name: str, min_value: Any = None,
                             max_value: Any = None, filtered_data_type: type | None = None) -> list[Struct]:
    """The elements :func:`by_attr_in_interval` leaves out."""
    inside = set(map(id, by_attr_in_interval(elements, attr_name, min_value, max_value, filtered_data_type)))
    return [e for e in _typed(elements, filtered_data_type) if id(e) not in inside]
