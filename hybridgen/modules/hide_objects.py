"""``object.Hide``: take selected objects out of every render and label (Blender's hide_render)."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import RunContext
from .base import Role
from .selecting import SelectingModule


@register_module("object.Hide")
class Hide(SelectingModule):
    """Removes the selected objects from the scene: no color, depth or segmentation sees them. Their instance
    ids are not given to other objects, so the remaining objects keep theirs."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="objects to hide (getter.Entity conditions, random_samples)"),
    )

    def run(self, context: RunContext) -> None:
        context.scene.remove(*self.selected(context))
