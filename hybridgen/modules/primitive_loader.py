"""``loader.PrimitiveLoader``: analytic shapes (cube, sphere, cylinder, cone, torus, plane)."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..run.context import RunContext
from ..scene.primitives import PRIMITIVES, make_primitive
from .base import Module, Role
from .placement import PLACEMENT_PARAMS, apply_placement, drawn_placement, placement_pose


def _color_check(value: object) -> str | None:
    if value is None:
        return None
    ok = isinstance(value, list) and len(value) in (3, 4) and all(
        isinstance(c, (int, float)) and not isinstance(c, bool) and 0 <= c <= 1 for c in value)
    return None if ok else f"must be [r, g, b] or [r, g, b, a] in 0..1, got {value!r}"


@register_module("loader.PrimitiveLoader")
class PrimitiveLoader(Module):
    """Adds one analytic shape; handy for quick scenes and tests without mesh files."""

    role = Role.LOADER

    params = (
        Param("shape", "str", choices=tuple(PRIMITIVES), doc="which shape"),
        Param("size", "float", 1.0, "m", "edge length (cube, plane) or diameter", check=positive),
        Param("color", "list|null", None, doc="base color, linear RGB(A) in 0..1", check=_color_check,
              sampleable=True),
        *PLACEMENT_PARAMS,
    )

    def run(self, context: RunContext) -> None:
        cfg = drawn_placement(self, context)
        obj = make_primitive(cfg["shape"], cfg["size"], name=cfg["name"], category_id=cfg["category_id"],
                             local2world=placement_pose(cfg), color=self.value(context, "color"),
                             attributes=cfg["attributes"])
        for placed in apply_placement([obj], cfg):
            context.scene.add(placed)
