"""``lighting.SurfaceLighting``: make selected surfaces emit light (the paper lit rooms by their ceiling)."""
from __future__ import annotations

import dataclasses

from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import RunContext
from .base import Role
from .selecting import SelectingModule


def _color(value: list) -> str | None:
    ok = len(value) in (3, 4) and all(isinstance(c, (int, float)) and c >= 0 for c in value)
    return None if ok else f"must be 3 numbers >= 0, got {value!r}"


@register_module("lighting.SurfaceLighting")
class SurfaceLighting(SelectingModule):
    """Selected objects emit ``emission_color`` x ``emission_strength`` (radiance, both sides).

    As BlenderProc's ``make_emissive`` (a mix on Light Path 'Is Camera Ray'), the emission lights the scene
    but the camera sees the surface's own material (``Material.emission_hidden_from_camera``);
    ``visible_to_camera: true`` (hybridgen only) shows the camera the glow as well.
    """

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="which objects emit (getter.Entity conditions)"),
        Param("emission_strength", "float", 10.0, doc="radiance scale", sampleable=True,
              check=lambda v: None if v >= 0 else f"must be >= 0, got {v}"),
        Param("emission_color", "list|null", None, doc="linear RGB; null: the object's base color",
              sampleable=True, check=lambda v: None if v is None else _color(v)),
        Param("keep_using_base_color", "bool", False, doc="when emission_color is null, emit the base color"),
        Param("visible_to_camera", "bool", False,
              doc="hybridgen only: the camera sees the emission too (BlenderProc: it sees the surface's material)"),
    )

    def run(self, context: RunContext) -> None:
        for obj in self.selected(context):
            color = self.value(context, "emission_color")
            if color is None:
                color = obj.material.base_color[:3] if self.config["keep_using_base_color"] else (1.0, 1.0, 1.0)
            obj.material = dataclasses.replace(obj.material, emission=tuple(float(c) for c in color[:3]),
                                               emission_strength=float(self.value(context, "emission_strength")),
                                               emission_hidden_from_camera=not self.config["visible_to_camera"])
