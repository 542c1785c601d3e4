"""``bproc.types.Struct``: a named Blender data block with custom properties (BlenderProc's StructUtility).

Names are unique per data kind as Blender makes them (``Cube``, ``Cube.001``; :meth:`Session.claim_name`).
Custom properties (``set_cp``/``get_cp``) hold any value; numbers can be keyed per frame, as Blender keys
``obj["key"]``. Attributes that Blender objects have (``name``, ``location`` ...) are read with
:meth:`Struct.get_attr`; a custom property may not shadow one (BlenderProc's rule).
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ...errors import InputError
from ..session import SESSION, Animated


class Struct:
    """A named data block. Subclasses set ``KIND`` (the name table: ``object``, ``material``) and list the
    Blender attributes :meth:`get_attr` reads in ``ATTRIBUTES``."""

    KIND: ClassVar[str] = "struct"
    ATTRIBUTES: ClassVar[tuple[str, ...]] = ("name",)

    def __init__(self, name: str) -> None:
        self._name = SESSION.claim_name(self.KIND, name)
        self._cps: dict[str, Animated] = {}
        self._valid = True

    def is_valid(self) -> bool:
        """False once the block was deleted."""
        return self._valid

    def set_name(self, name: str) -> None:
        """Rename; a name another block of this kind holds gets Blender's next ``.NNN`` suffix."""
        self._name = SESSION.claim_name(self.KIND, name, current=self._name)

    def get_name(self) -> str:
        return self._name

    def set_cp(self, key: str, value: Any, frame: int | None = None) -> None:
        """Set custom property ``key``; an int, float or bool value is keyed at ``frame`` when one is given."""
        if key in self.ATTRIBUTES:
            raise InputError(f"custom property '{key}' of '{self._name}': '{key}' is an attribute of the object "
                             "and cannot be a custom property (as in BlenderProc)")
        prop = self._cps.setdefault(key, Animated(value))
        keyed = frame is not None and isinstance(value, (bool, int, float, np.integer, np.floating))
        prop.set(value, frame if keyed else None)

    def get_cp(self, key: str, frame: int | None = None) -> Any:
        """Custom property ``key`` (its keyed value at ``frame``, when given); a missing key is an error."""
        if key not in self._cps:
            raise InputError(f"'{self._name}' has no custom property '{key}'")
        return self._cps[key].at(frame)

    def del_cp(self, key: str) -> None:
        if key not in self._cps:
            raise InputError(f"'{self._name}' has no custom property '{key}'")
        del self._cps[key]

    def has_cp(self, key: str) -> bool:
        return key in self._cps

    def get_all_cps(self) -> dict[str, Any]:
        """Every custom property's current value."""
        return {key: prop.value for key, prop in self._cps.items()}

    def clear_all_cps(self) -> None:
        self._cps.clear()

    def get_attr(self, attr_name: str) -> Any:
        """The Blender attribute ``attr_name`` (one of ``ATTRIBUTES``; vectors as numpy arrays)."""
        if attr_name not in self.ATTRIBUTES:
            raise InputError(f"'{self._name}' has no attribute '{attr_name}' hybridgen knows "
                             f"(known: {', '.join(self.ATTRIBUTES)})")
        return self._attribute(attr_name)

    def _attribute(self, attr_name: str) -> Any:
        return self._name

    def clear_keyframes(self) -> None:
        """Drop every keyframe of this block (``bproc.utility.reset_keyframes``); current values stay."""
        for prop in self._cps.values():
            prop.keys.clear()

    def _invalidate(self) -> None:
        SESSION.release_name(self.KIND, self._name)
        self._valid = False

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self._name!r}>"
