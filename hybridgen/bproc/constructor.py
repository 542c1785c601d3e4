"""``bproc.constructor``: ``construct_random_room`` is not implemented yet (raises one line)."""
from __future__ import annotations

from .types.unsupported import module_getattr

__getattr__ = module_getattr("constructor", ["construct_random_room"])
