"""Config values are nested dicts and lists: rebuild one with a function applied to its items, each named by
its key path (``cam_poses[0].location``) for error messages."""
from __future__ import annotations

from typing import Any, Callable


def map_nested(value: Any, item: Callable[[Any, str], Any], where: str = "",
               is_item: Callable[[Any], bool] = lambda value: False) -> Any:
    """``value`` with dicts and lists rebuilt (same order) and ``item(x, path)`` in place of everything else,
    and of dicts or lists for which ``is_item`` is true (e.g. a sampler dict); ``where`` is ``value``'s path."""
    if not is_item(value):
        if isinstance(value, dict):
            return {k: map_nested(v, item, f"{where}.{k}" if where else str(k), is_item) for k, v in value.items()}
        if isinstance(value, list):
            return [map_nested(v, item, f"{where}[{i}]", is_item) for i, v in enumerate(value)]
    return item(value, where)
