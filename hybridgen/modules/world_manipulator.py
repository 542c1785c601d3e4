"""``manipulators.WorldManipulator``: the world background (BlenderProc's WorldManipulator keys)."""
from __future__ import annotations

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import RunContext
from .base import Module, Role


@register_module("manipulators.WorldManipulator")
class WorldManipulator(Module):
    """Sets the world background color and strength; ``cf_set_world_category_id`` is accepted with a notice
    (hybridgen's segmentation background is always 0)."""

    role = Role.MANIPULATOR

    params = (
        Param("color", "list|null", None, sampleable=True, doc="background radiance, linear RGB(A)"),
        Param("strength", "float|null", None, sampleable=True, doc="multiplies the background"),
        Param("cf_set_world_category_id", "int|null", None,
              doc="BlenderProc's category id of the background; hybridgen's background is 0 in every segmap"),
    )

    def run(self, context: RunContext) -> None:
        world = context.scene.world
        color = self.value(context, "color")
        if color is not None:
            world.color = tuple(float(c) for c in color[:3])  # type: ignore[assignment]
        strength = self.value(context, "strength")
        if strength is not None:
            world.strength = float(strength)
        if self.config["cf_set_world_category_id"] not in (None, 0):
            notice("background pixels stay 0 in hybridgen's segmaps (no object there)", module=self.module_name,
                   index=self.index, key="cf_set_world_category_id")
