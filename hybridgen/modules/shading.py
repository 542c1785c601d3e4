"""``object.Shading``: Blender's shading modes (:mod:`hybridgen.scene.shading`) on objects.

BlenderProc sets them with ``cf_set_shading`` (``FLAT``, ``SMOOTH``, ``AUTO`` with
``cf_shading_auto_smooth_angle_in_deg``) on a loader (the objects it loads) or on EntityManipulator (the
selected objects). This module takes either ``selector`` (objects of the scene) or ``loader`` (a nested
``{module: loader.X, config: {...}}`` entry that runs here; the objects it adds are shaded). Objects sharing
mesh arrays (instances of one model) keep sharing the shaded arrays.
"""
from __future__ import annotations

from typing import Any

from ..config.paths import resolve_module_paths
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from ..scene.mesh_object import MeshObject
from ..scene.shading import SHADING_MODES, ShadedMesh, shade
from .base import Module, Role
from .camera_object_sampler import nested_module


def _loader_problem(entry: Any) -> str | None:
    if entry is None:
        return None
    try:
        nested_module(entry, 0)
    except ConfigError as exc:
        return f"{exc.key}: {exc.detail}" if exc.key else exc.detail
    return None


def shade_objects(objects: list[MeshObject], mode: str, angle_deg: float) -> None:
    """Shade ``objects`` in place; objects with the same arrays get the same shaded arrays."""
    done: dict[tuple[int, ...], ShadedMesh] = {}
    for obj in objects:
        key = (id(obj.vertices), id(obj.faces), id(obj.uvs), id(obj.vertex_colors))
        if key not in done:
            done[key] = shade(obj.vertices, obj.faces, mode, angle_deg, obj.uvs, obj.vertex_colors)
        shaded = done[key]
        obj.vertices, obj.faces, obj.vertex_normals = shaded.vertices, shaded.faces, shaded.vertex_normals
        obj.uvs, obj.vertex_colors = shaded.uvs, shaded.vertex_colors
        obj.forget_derived()


@register_module("object.Shading")
class Shading(Module):
    """Sets Blender's shading mode (FLAT, SMOOTH, AUTO) of selected or freshly loaded objects."""

    role = Role.MANIPULATOR

    params = (
        Param("mode", "str", choices=SHADING_MODES, doc="FLAT: face normals; SMOOTH: vertex normals; AUTO: smooth "
              "up to auto_smooth_angle"),
        Param("auto_smooth_angle", "float", 30.0, "deg", "AUTO: edges sharper than this stay sharp",
              check=lambda v: None if 0 <= v <= 180 else "must be in 0..180"),
        Param("selector", "dict|list|null", None, doc="objects to shade (getter.Entity conditions)"),
        Param("loader", "dict|null", None, check=_loader_problem,
              doc="{module: loader.X, config: {...}}: run this loader here and shade what it adds"),
    )

    def __init__(self, config: dict[str, Any], index: int) -> None:
        super().__init__(config, index)
        if (config["selector"] is None) == (config["loader"] is None):
            raise ConfigError("give exactly one of selector and loader", key="selector")
        self.loader = nested_module(config["loader"], index) if config["loader"] is not None else None
        if self.loader is not None:
            self.role = self.loader.role

    def prepare(self, context: RunContext) -> None:
        if self.loader is not None:
            if context.config is not None:
                resolve_module_paths(self.loader.params, self.loader.config, context.config.path)
            self.loader.prepare(context)

    def run(self, context: RunContext) -> None:
        if self.loader is None:
            objects = parse_selector(self.config["selector"], "selector").select(context.scene.objects, context.rng)
        else:
            before = {id(o) for o in context.scene.objects}
            self.loader.run(context)
            objects = [o for o in context.scene.objects if id(o) not in before]
        shade_objects(objects, self.config["mode"], self.config["auto_smooth_angle"])

