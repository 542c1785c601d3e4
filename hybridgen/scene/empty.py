"""Empties: named poses without geometry (Blender's empty objects, BlenderProc's ``constructor.BasicEmptyInitializer``).

An empty marks a place - a camera's focus point, a location to look at. It has a name, a ``local2world`` pose
(metres, world Z up), Blender's display type (``plain_axes``, ``arrows``, ... - how Blender draws it in its
viewport, nothing more) and custom attributes. Empties live in ``Scene.empties``, apart from the mesh objects:
no renderer draws or path-traces them, they get no instance id and they are not in ``object_states`` (BlenderProc's
ObjectStateWriter writes mesh objects only). Selectors (``getter.Entity`` conditions) find them where a module
asks for an entity rather than a mesh (``depth_of_field.focal_object``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

EMPTY_TYPES = ("plain_axes", "arrows", "single_arrow", "circle", "cube", "sphere", "cone")
"""Blender's empty display types (BlenderProc's ``type`` values)."""


@dataclass(eq=False)
class Empty:
    """A named pose without geometry."""

    name: str
    local2world: np.ndarray = field(default_factory=lambda: np.eye(4))
    display_type: str = "plain_axes"
    attributes: dict[str, Any] = field(default_factory=dict)
    category_id: int | None = None  # never set by hybridgen; selectors read it like an object's
    instance_id: int = 0  # empties are never drawn: no instance id

    def __post_init__(self) -> None:
        self.local2world = np.array(self.local2world, dtype=np.float64).reshape(4, 4)

    @property
    def location(self) -> np.ndarray:
        """The empty's origin in world coordinates (m)."""
        return self.local2world[:3, 3].copy()
