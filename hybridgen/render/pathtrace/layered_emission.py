"""Emission under the coat and sheen: Blender 4.2's Principled BSDF emits Emission x Strength times what its sheen
and coat layers leave (Cycles' ``emission_setup`` after the two layers, the weight the layers below get), which
depends on the direction the surface is seen from.

Cycles computes that weight only where it sets up the surface's closures: at a camera ray's or a BSDF sample's hit
from which the path goes on. Where it only collects emission - a light sample (next-event estimation) and a
path's last vertex (bounce limit reached) - it evaluates the shader without closure storage (``max_closures`` 0
for ``PATH_RAY_EMISSION`` / ``PATH_RAY_TERMINATE``), the layers are not set up, and the emission keeps only the
coat tint's absorption (applied outside the closure's allocation). Measured with bpy 4.2
(tools/principled_vs_cycles.py --group emission, docs/principled_bsdf.md): a floor lit by a coated emitter alone is
0.945 of Cycles with the full weight on light samples too, 0.992 without, 1.074 with no weight at all.

hybridgen's emitters are Mitsuba ``area`` emitters of a fixed radiance (:mod:`.material_emission`), so hybridgen's
path integrator (:mod:`.clamped_path`, JIT variants) does the same where it collects emission from a shape listed
here - an emissive object whose material has a coat or a sheen (both sides' shapes): at a hit the path continues
from, the weight for the hit's view direction from the material's own Principled BSDF
(:meth:`~.principled_bsdf.PrincipledBSDF.emission_weight`: sheen then coat, each for the view cosine to its own
normal, maps included); at light samples and last vertices the coat tint's absorption alone (a light sample's
found by intersecting its shadow ray once more, only in scenes with a tinted coated emitter).

Scenes without such emitters trace none of this (same kernels and bytes as before). Light selection keeps the
emitters' unweighted power. Mitsuba's own integrators (``scalar_rgb``) have no coat or sheen at all.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...scene.material import Material
from ...scene.scene import Scene
from .material_emission import emitted_radiance


def layered(material: Material) -> bool:
    """Whether ``material``'s emission lies under a coat or a sheen (a weight > 0 of either); never for a mix of
    materials, whose components cannot emit under their layers (:func:`hybridgen.scene.material_mix.unsupported_in_mix`)."""
    if material.mixes:
        return False
    return any(isinstance(material.extra.get(key, 0.0), (int, float)) and material.extra.get(key, 0.0) > 0
               for key in ("coat_weight", "sheen_weight"))


@dataclass
class LayeredEmitter:
    """One emitting shape, its emitter and the Principled BSDF (Mitsuba object) that weighs its emission."""

    shape: Any
    emitter: Any
    bsdf: Any
    tinted: bool  # a coat with a tint other than white: light samples see its absorption


def emitters(scene: Scene, description: dict[str, Any]) -> list[LayeredEmitter]:
    """The shapes of ``description`` (:func:`~.mitsuba_scene.scene_dict`, loaded) whose emission lies under a coat
    or sheen, each with a Principled BSDF of its material (only when hybridgen's Principled BSDF renders)."""
    from . import principled_material

    if not principled_material.enabled():
        return []
    out = []
    for obj in scene.objects:
        if not (layered(obj.material) and np.any(emitted_radiance(obj) > 0)):
            continue
        bsdf = _weighing_bsdf(obj.material, obj.name)
        extra = obj.material.extra
        tint = extra.get("coat_weight", 0.0) > 0 and tuple(extra.get("coat_tint", (1.0, 1.0, 1.0))) != (1.0, 1.0, 1.0)
        for key in (f"object_{obj.instance_id}", f"object_{obj.instance_id}_back"):
            shape = description.get(key)
            if shape is not None and shape.emitter() is not None:
                out.append(LayeredEmitter(shape, shape.emitter(), bsdf, bool(tint)))
    return out


def _weighing_bsdf(material: Material, owner: str) -> Any:
    """hybridgen's Principled BSDF of ``material``'s layers (its base inputs do not change the weight) with its
    normal maps inside (the sheen's normal mixes the base's, the coat's is its own)."""
    import mitsuba as mi

    from .mitsuba_materials import data_texture
    from .principled_material import plugin_dict

    bsdf = plugin_dict(material, owner, {"type": "rgb", "value": [0.5, 0.5, 0.5]}, 0.5, 0.0, 0.5)
    for key, slot in (("normal_map", "normal_texture"), ("coat_normal_map", "coat_normal_texture")):
        if getattr(material, slot) is not None:
            bsdf[key] = data_texture(getattr(material, slot), owner, slot, channels=3,
                                     invert_green=material.normal_y_down)
    return mi.load_dict(bsdf)


def weight(entries: list[LayeredEmitter], si: Any, active: Any, layered: Any) -> Any:
    """The emission weight (Color3f) at surface interactions ``si`` seen from ``si.wi``: the layers' where
    ``layered`` (the path goes on from there), the coat tint's absorption alone elsewhere; 1 off the listed
    shapes."""
    import drjit as dr
    import mitsuba as mi

    result = mi.Color3f(1.0)
    for entry in entries:
        on = active & (si.shape == mi.ShapePtr(entry.shape))
        if entry.tinted:
            result = dr.select(on, entry.bsdf.emission_weight(si, on, False), result)
        result = dr.select(on & layered, entry.bsdf.emission_weight(si, on & layered), result)
    return result


def tinted(entries: list[LayeredEmitter]) -> bool:
    """Whether any listed emitter has a coat tint (which light samples see: :func:`light_weight`)."""
    return any(entry.tinted for entry in entries)


def light_weight(entries: list[LayeredEmitter], scene: Any, si: Any, ds: Any, active: Any) -> Any:
    """The coat tint's absorption for light samples ``ds`` taken from ``si`` on tinted emitters: at the light point
    the ray from ``si`` along ``ds.d`` reaches (a second intersection: its shading frame and texture coordinates),
    seen from ``si``; 1 for other emitters and where the ray finds no listed shape."""
    import mitsuba as mi

    sampled = mi.Bool(False)
    for entry in entries:
        if entry.tinted:
            sampled |= ds.emitter == mi.EmitterPtr(entry.emitter)
    active = active & sampled
    hit = scene.ray_intersect(si.spawn_ray(ds.d), active)
    return weight(entries, hit, active & hit.is_valid(), mi.Bool(False))
