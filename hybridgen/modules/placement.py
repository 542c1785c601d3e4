"""Parameters every object loader shares (name, labels, pose) and their use."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..config.material_config import apply_material_config
from ..config.schema import Param
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from .base import Module
from ..scene.frames import object_pose


def _scale_check(value: Any) -> str | None:
    if isinstance(value, list):
        if len(value) != 3 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            return f"must be a number or a list of 3 numbers, got {value!r}"
        values = value
    else:
        values = [value]
    return None if all(v != 0 for v in values) else f"must be non-zero, got {value!r}"


PLACEMENT_PARAMS: tuple[Param, ...] = (
    Param("name", "str|null", None, doc="object name (several parts of one file get '<name>.<part>')"),
    Param("category_id", "int|null", None, doc="class label written to category_id_segmaps"),
    Param("attributes", "dict", {}, doc="custom attributes (numeric ones can be segmap keys via map_by)"),
    Param("location", "vec3", [0.0, 0.0, 0.0], "m", "position in world coordinates", sampleable=True),
    Param("rotation", "vec3", [0.0, 0.0, 0.0], "rad", "Euler XYZ angles, as in Blender", sampleable=True),
    Param("scale", "float|list", 1.0, "", "uniform scale or [sx, sy, sz]", check=_scale_check, sampleable=True),
    Param("material", "dict", {}, sampleable=True,
          doc="principled values replacing the file's: base_color, roughness, metallic, specular, transmission, ior, "
              "alpha, alpha_mode, emission, emission_strength, and maps (paths): base_color_texture, "
              "roughness_texture, metallic_texture, alpha_texture, normal_texture (normal_y_down), "
              "displacement_texture (displacement_scale), specular_texture, emission_texture, coat_normal_texture"),
)


def drawn_placement(module: Module, context: RunContext) -> dict[str, Any]:
    """The loader's config with location, rotation, scale and material drawn (once per loaded file)."""
    return {**module.config, **{p.name: module.value(context, p.name) for p in PLACEMENT_PARAMS if p.sampleable}}


def apply_placement(objects: list[MeshObject], config: dict[str, Any]) -> list[MeshObject]:
    """Apply the loader's ``material`` overrides to freshly loaded objects (poses are set at load)."""
    if config["material"]:
        for obj in objects:
            obj.material = apply_material_config(obj.material, config["material"])
    return objects


def placement_pose(config: dict[str, Any]) -> np.ndarray:
    """local2world 4x4 from a loader's location, rotation and scale."""
    return object_pose(config["location"], config["rotation"], config["scale"])
