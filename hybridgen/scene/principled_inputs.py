"""The Principled BSDF inputs a :class:`~hybridgen.scene.material.Material` carries in ``extra``: Blender 4.2's inputs
that have no field of their own, under Blender's names in snake case, with Blender's defaults and ranges.

Blender clamps each value into its range where it renders (Cycles saturates weights and roughness); hybridgen's
renderer does the same (:mod:`hybridgen.render.pathtrace.principled_bsdf`). Checking here only refuses what no
renderer can use: wrong types, non-finite numbers, negative radii, unknown names. Colors are linear RGB;
``subsurface_radius`` is a per-channel distance (m, times ``subsurface_scale``). ``subsurface_method`` is the
node's property (not an input): ``BURLEY``, ``RANDOM_WALK`` (Blender 4.2's default) or ``RANDOM_WALK_SKIN``.

:data:`INPUTS` also names each input as Blender 4 does and as Blender 3 did where the input existed there under
another name (BlenderProc's ``set_principled_shader_value`` and v1 configs' ``cf_set_*`` take either; a
Blender 3 name means the Blender 4 input it became, as Blender's own file conversion maps it).
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class PrincipledInput:
    """One input: ``key`` in ``Material.extra``, Blender 4's socket name, Blender 3 names, its default, its kind
    (``value``, ``color``: RGB, ``vector``: 3 numbers, ``choice``) and the closed range Blender renders."""

    key: str
    blender: str
    default: Any
    kind: str = "value"
    low: float = -math.inf
    high: float = math.inf
    blender3: tuple[str, ...] = ()


INPUTS = (
    PrincipledInput("specular_tint", "Specular Tint", (1.0, 1.0, 1.0), "color", 0.0),
    PrincipledInput("anisotropic", "Anisotropic", 0.0, low=0.0, high=1.0),
    PrincipledInput("anisotropic_rotation", "Anisotropic Rotation", 0.0),
    PrincipledInput("coat_weight", "Coat Weight", 0.0, low=0.0, blender3=("Clearcoat",)),
    PrincipledInput("coat_roughness", "Coat Roughness", 0.03, low=0.0, high=1.0, blender3=("Clearcoat Roughness",)),
    PrincipledInput("coat_ior", "Coat IOR", 1.5, low=1.0),
    PrincipledInput("coat_tint", "Coat Tint", (1.0, 1.0, 1.0), "color", 0.0),
    PrincipledInput("sheen_weight", "Sheen Weight", 0.0, low=0.0, blender3=("Sheen",)),
    PrincipledInput("sheen_roughness", "Sheen Roughness", 0.5, low=0.0, high=1.0),
    PrincipledInput("sheen_tint", "Sheen Tint", (1.0, 1.0, 1.0), "color", 0.0),
    PrincipledInput("subsurface_weight", "Subsurface Weight", 0.0, low=0.0, high=1.0, blender3=("Subsurface",)),
    PrincipledInput("subsurface_radius", "Subsurface Radius", (1.0, 0.2, 0.1), "vector", 0.0),
    PrincipledInput("subsurface_scale", "Subsurface Scale", 0.05, low=0.0),
    PrincipledInput("subsurface_ior", "Subsurface IOR", 1.4, low=1.01, high=3.8),
    PrincipledInput("subsurface_anisotropy", "Subsurface Anisotropy", 0.0, low=0.0, high=1.0),
    PrincipledInput("subsurface_method", "subsurface_method", "RANDOM_WALK", "choice"),
)
"""Every ``extra`` input, in Blender's socket order."""
BY_KEY = {entry.key: entry for entry in INPUTS}
BY_BLENDER_NAME = {name: entry for entry in INPUTS if entry.kind != "choice"
                   for name in (entry.blender, *entry.blender3)}
"""Blender 4 and Blender 3 socket names -> the input."""
SUBSURFACE_METHODS = ("BURLEY", "RANDOM_WALK", "RANDOM_WALK_SKIN")
DEFAULTS = {entry.key: entry.default for entry in INPUTS}
"""``extra`` key -> Blender 4.2's default."""
COLOR_KEYS = tuple(entry.key for entry in INPUTS if entry.kind in ("color", "vector"))


def checked(key: str, value: Any) -> Any:
    """``value`` of the ``extra`` input ``key`` as hybridgen keeps it (a float, an RGB / XYZ tuple of floats, or
    the method's name); ``ValueError`` with the reason when it is not one (the caller names the material)."""
    entry = BY_KEY.get(key)
    if entry is None:
        raise ValueError(f"is not a Principled input hybridgen knows (known: {', '.join(BY_KEY)})")
    if entry.kind == "choice":
        if value not in SUBSURFACE_METHODS:
            raise ValueError(f"must be one of {', '.join(SUBSURFACE_METHODS)}, got {value!r}")
        return value
    if entry.kind in ("color", "vector"):
        if isinstance(value, numbers.Real) and not isinstance(value, bool) and entry.kind == "color":
            raise ValueError(f"takes an RGB color (Blender 4), got the number {value!r} (Blender 3's 0..1 "
                             "tint toward the base color is not supported)")
        try:
            triple = tuple(float(v) for v in value)
        except (TypeError, ValueError):
            triple = ()
        if len(triple) == 4 and entry.kind == "color":
            triple = triple[:3]  # RGBA as Blender's color sockets hold it: alpha unused
        if len(triple) != 3 or not all(math.isfinite(v) for v in triple):
            raise ValueError(f"must be 3 finite numbers, got {value!r}")
        if entry.kind == "vector" and min(triple) < 0:
            raise ValueError(f"must be >= 0 per channel, got {value!r}")
        return triple
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise ValueError(f"must be a finite number, got {value!r}")
    return float(value)


_GATES = (("coat_", "coat_weight"), ("sheen_", "sheen_weight"), ("subsurface_", "subsurface_weight"),
          ("anisotropic_rotation", "anisotropic"))
"""(key prefix, the weight that switches those inputs on): a layer's other inputs matter only where it is."""


def from_node(values: dict[str, Any]) -> dict[str, Any]:
    """``extra`` of a Principled BSDF node read from a file (``values``: key -> socket value, as :data:`BY_KEY`
    names them): the checked values that differ from Blender's defaults, a layer's inputs only where its weight
    is above 0 (a coat roughness without a coat changes nothing, and a material without any stays Lambertian
    where hybridgen renders it so). Values no renderer can use are left out."""
    out: dict[str, Any] = {}
    for key, value in values.items():
        try:
            value = checked(key, value)
        except ValueError:
            continue
        if value != DEFAULTS[key]:
            out[key] = value
    for prefix, weight in _GATES:
        if out.get(weight, 0.0) <= 0:
            out = {k: v for k, v in out.items() if not k.startswith(prefix)}
    return out

