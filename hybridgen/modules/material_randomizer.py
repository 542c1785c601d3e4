"""``manipulators.MaterialRandomizer``: give selected objects random materials (BlenderProc's
EntityManipulator ``cf_randomize_materials``).

Each selected object gets, with probability ``randomization_level``, a material drawn from
``materials_to_replace_with`` (BlenderProc getter.Material conditions over the run's material library and
the scene's object materials; ``random_samples`` narrows the candidates first). ``mode: once_for_all``
draws one material for every selected object, ``once_for_each`` one per object.
"""
from __future__ import annotations

import copy
from typing import Any

import numpy as np

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import InputError
from ..run.context import RunContext
from ..scene.material import Material
from .material_library import LibraryMaterial, material_library, material_matches
from .base import Role
from .selecting import SelectingModule


def _check_source(value: Any) -> str | None:
    if value is None:
        return None
    if not isinstance(value, dict) or value.get("provider", "getter.Material") != "getter.Material":
        return "must be a getter.Material selector {provider: getter.Material, conditions, random_samples}"
    unknown = [k for k in value if k not in ("provider", "conditions", "random_samples", "check_empty")]
    return f"unknown key(s) {unknown}" if unknown else None


def planar_uvs(vertices: np.ndarray) -> np.ndarray:
    """UVs of a projection along local Z over the XY bounding box: a Blender plane's own UVs ([0, 1]^2)."""
    xy = np.asarray(vertices, dtype=np.float64)[:, :2]
    low, span = xy.min(axis=0), np.ptp(xy, axis=0)
    return (xy - low) / np.where(span > 0, span, 1.0)


@register_module("manipulators.MaterialRandomizer")
class MaterialRandomizer(SelectingModule):
    """Replaces the materials of selected objects by random candidates (see the module doc)."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="objects whose materials are replaced (getter.Entity)"),
        Param("randomization_level", "float", 0.2, doc="probability that an object's material is replaced",
              check=lambda v: None if 0 <= v <= 1 else "must be in 0..1"),
        Param("materials_to_replace_with", "dict|null", None, check=_check_source,
              doc="candidates (getter.Material); default: every material of the library and the scene"),
        Param("mode", "str", "once_for_each", choices=("once_for_each", "once_for_all")),
    )

    def _candidates(self, context: RunContext) -> list[Material]:
        source = self.config["materials_to_replace_with"] or {}
        pool: list[LibraryMaterial] = list(material_library(context))
        seen = {id(m.material) for m in pool}
        for obj in context.scene.objects:
            if id(obj.material) not in seen:
                seen.add(id(obj.material))
                pool.append(LibraryMaterial(obj.material))
        chosen = [m.material for m in pool if material_matches(m, source.get("conditions"))]
        count = source.get("random_samples")
        if count is not None and len(chosen) > count:
            picks = sorted(context.rng.choice(len(chosen), size=int(count), replace=False))
            chosen = [chosen[i] for i in picks]
        if not chosen:
            raise InputError(f"materials_to_replace_with matches no material ({source.get('conditions')!r}); "
                             "load some with loader.CCMaterialLoader")
        return chosen

    def run(self, context: RunContext) -> None:
        objects = self.selected(context)
        if not objects:
            return
        candidates = self._candidates(context)
        shared = candidates[int(context.rng.integers(len(candidates)))]
        for obj in objects:
            if context.rng.uniform() >= self.config["randomization_level"]:
                continue
            pick = shared if self.config["mode"] == "once_for_all" else \
                candidates[int(context.rng.integers(len(candidates)))]
            if pick.uses_uvs and obj.uvs is None:
                obj.uvs = planar_uvs(obj.vertices)
                notice(f"object '{obj.name}' has no UVs: the texture is projected along its local Z axis",
                       module=self.module_name, index=self.index, key="selector")
            obj.material = copy.copy(pick)
