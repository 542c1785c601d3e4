"""Another material mixed into a material's surface (BlenderProc 2.8's ``Material.infuse_material``).

BlenderProc copies the other material's node tree into a group and puts a Mix Shader between the material's
surface shader and the Material Output. :attr:`hybridgen.scene.material.Material.mixes` holds those steps in order;
each makes the surface ``keep x (the surface so far) + weight x (the other material)``, a weighted sum of closures
(Cycles' Mix Shader: the BSDFs, their emission and, in its Diffuse Color pass, their diffuse colors):

- ``mode="mix"``: keep ``1 - f``, weight ``f``, the factor ``f`` (``mix_strength``) clamped to [0, 1];
- ``mode="add"``: BlenderProc links the material's own shader into the Mix Shader's factor, a link Blender marks
  invalid and Cycles ignores, so the factor is its default 0.5 and the second shader input stays empty: keep 0,
  weight 0.5 - the other material at half strength, the material's own surface gone (measured with the real
  BlenderProc: tools/infuse_vs_blenderproc.py).

The surface is then ``sum_k w_k x material_k`` over :func:`components` (weights summing to at most 1; what is left
absorbs, as an empty shader input does).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

Material = Any
"""A :class:`hybridgen.scene.material.Material` (not imported: that module imports this one)."""

MODES = {"mix", "add"}


@dataclass(frozen=True, eq=False)
class MaterialMix:
    """One Mix Shader step: the surface becomes ``keep x surface + weight x material`` (``material`` a snapshot of
    the infused material, its own mixes included)."""

    material: Material
    weight: float
    keep: float

    @staticmethod
    def of_mode(material: Material, mode: str, mix_strength: float) -> "MaterialMix":
        """The step BlenderProc's ``infuse_material(material, mode, mix_strength)`` builds (module docstring)."""
        if mode == "add":
            return MaterialMix(material, 0.5, 0.0)
        factor = min(max(float(mix_strength), 0.0), 1.0)
        return MaterialMix(material, factor, 1.0 - factor)


def components(material: Material) -> list[tuple[Material, float]]:
    """(material without mixes, weight) pairs whose weighted sum ``material``'s surface is, the material's own
    surface first; weights in [0, 1] summing to at most 1."""
    out = [(replace(material, mixes=(), extra=dict(material.extra)), 1.0)]
    for mix in material.mixes:
        out = [(m, w * mix.keep) for m, w in out] + [(m, w * mix.weight) for m, w in components(mix.material)]
    return out


def unsupported_in_mix(material: Material) -> str | None:
    """Why a component of a mix cannot be rendered by hybridgen (None when it can): transparency, displacement,
    emission from an image or hidden from the camera do not mix yet."""
    if material.alpha_texture is not None or material.alpha < 1.0:
        return "transparency (alpha)"
    if material.displacement_texture is not None:
        return "displacement"
    if material.emission_strength != 0 and (material.emission_texture is not None
                                            or material.emission_hidden_from_camera):
        return "emission from an image or hidden from the camera (make_emissive)"
    layered = any(isinstance(material.extra.get(key, 0.0), (int, float)) and material.extra.get(key, 0.0) > 0
                  for key in ("coat_weight", "sheen_weight"))
    if layered and material.emission_strength != 0 and any(c != 0 for c in material.emission):
        return "emission under a coat or sheen"
    return None
