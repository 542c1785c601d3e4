"""``bproc.utility.UndoAfterExecution``: everything a block changes in the session is undone when it ends, as
Blender's undo step does for BlenderProc.

On entry the session (:data:`~hybridgen.bproc.session.SESSION`: its objects, materials, name tables, frame range,
camera poses and settings, world, renderer settings) and the state of every live data block (pose, keyframes,
custom properties, mesh parts, material slots and values) are copied; on exit they are put back into the same
Python objects, so references the script held before the block stay valid and see the old state, as BlenderProc
re-points its wrappers by name. Blocks created inside the block are gone afterwards (``is_valid()`` False).

Copies: containers, keyframed values and small arrays are copied; a data block inside a value stays the same
object (its own state is restored separately); large arrays (mesh and texture data, which this layer replaces
rather than edits in place) and objects that cannot be copied are kept as they are.
"""
from __future__ import annotations

import copy
from types import TracebackType
from typing import Any

import numpy as np

from .session import SESSION, Animated

SMALL_ARRAY = 4096
"""Arrays with at most this many elements are copied; larger ones are shared."""


def _snapshot(value: Any, blocks: set[int], seen: dict[int, Any]) -> Any:
    """A copy of ``value`` deep enough to undo this layer's changes (see the module documentation)."""
    if id(value) in blocks or value is None or isinstance(value, (str, bytes, int, float, bool, complex)):
        return value
    if id(value) in seen:
        return seen[id(value)]
    if isinstance(value, np.ndarray):
        copied: Any = value.copy() if value.size <= SMALL_ARRAY else value
    elif isinstance(value, dict):
        copied = seen[id(value)] = type(value)()
        copied.update({key: _snapshot(item, blocks, seen) for key, item in value.items()})
    elif isinstance(value, tuple) and hasattr(value, "_fields"):  # a named tuple
        copied = type(value)(*(_snapshot(item, blocks, seen) for item in value))
    elif isinstance(value, (list, set, tuple, frozenset)):
        copied = type(value)(_snapshot(item, blocks, seen) for item in value)
    elif isinstance(value, Animated):
        copied = Animated(_snapshot(value.value, blocks, seen))
        copied.keys = _snapshot(value.keys, blocks, seen)
    elif hasattr(value, "__dict__") and not isinstance(value, type):
        try:
            copied = copy.copy(value)
            seen[id(value)] = copied
            copied.__dict__ = _snapshot(value.__dict__, blocks, seen)
        except Exception:  # an object that cannot be copied (a native handle, a read-only dict): kept as it is
            seen[id(value)] = value
            return value
    else:
        copied = value
    seen[id(value)] = copied
    return copied


class UndoAfterExecution:
    """``with UndoAfterExecution():`` undoes the block's changes to the session when it ends (see the module
    documentation); ``perform_undo_op=False`` undoes nothing. ``check_point_name`` names Blender's undo step and
    changes nothing here."""

    def __init__(self, check_point_name: str | None = None, perform_undo_op: bool = True) -> None:
        self.check_point_name = check_point_name
        self._perform_undo_op = perform_undo_op
        self._saved: list[tuple[Any, dict[str, Any]]] = []

    def __enter__(self) -> "UndoAfterExecution":
        if self._perform_undo_op:
            live = [*SESSION.entities, *SESSION.materials]
            blocks = {id(block) for block in live}
            seen: dict[int, Any] = {}
            self._saved = [(SESSION, _snapshot(SESSION.__dict__, blocks, seen))]
            self._saved += [(block, _snapshot(block.__dict__, blocks, seen)) for block in live]
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        if not self._perform_undo_op:
            return
        before = {id(block) for block, _ in self._saved}
        for block in [*SESSION.entities, *SESSION.materials]:
            if id(block) not in before:
                block._valid = False
        for target, state in self._saved:
            target.__dict__.clear()
            target.__dict__.update(state)
        self._saved = []
