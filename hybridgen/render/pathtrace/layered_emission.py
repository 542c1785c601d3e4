"""Emission under the coat and sheen: Blender 4.2's Principled BSDF emits Emission x Strength times what its sheen
and coat layers leave (Cycles' ``emission_setup`` after the two layers, the weight the layers below get), which
depends on the direction the surface is seen from.

hybridgen's emitters are Mitsuba ``area`` emitters of a fixed radiance (:mod:`.material_emission`), so hybridgen's
path integrator (:mod:`.clamped_path`, JIT variants) applies that weight where it collects emission from a shape
listed here - an emissive object whose material has a coat or a sheen (both sides' shapes):

- a hit (camera ray or BSDF sample): the weight for the hit's view direction, from the material's own Principled
  BSDF (:meth:`~.principled_bsdf.PrincipledBSDF.emission_weight`: sheen then coat, each for the view cosine to its
  own normal, maps included);
- a light sample (next-event estimation): the shadow ray is intersected once more to find the light point's
  shading frame and the weight computed there for the direction towards the shaded point - the same value a BSDF
  sample reaching that point collects, so both strategies and their MIS weights agree.

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
    """Whether ``material``'s emission lies under a coat or a sheen (a weight > 0 of either)."""
    return any(isinstance(material.extra.get(key, 0.0), (int, float)) and material.extra.get(key, 0.0) > 0
               for key in ("coat_weight", "sheen_weight"))


@dataclass
class LayeredEmitter:
    """One emitting shape, its emitter and the Principled BSDF (Mitsuba object) that weighs its emission."""

    shape: Any
    emitter: Any
    bsdf: Any


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
        for key in (f"object_{obj.instance_id}", f"object_{obj.instance_id}_back"):
            shape = description.get(key)
            if shape is not None and shape.emitter() is not None:
                out.append(LayeredEmitter(shape, shape.emitter(), bsdf))
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


def weight(entries: list[LayeredEmitter], si: Any, active: Any) -> Any:
    """The emission weight (Color3f) at surface interactions ``si`` seen from ``si.wi``: 1 off the listed shapes."""
    import drjit as dr
    import mitsuba as mi

    result = mi.Color3f(1.0)
    for entry in entries:
        on = active & (si.shape == mi.ShapePtr(entry.shape))
        result = dr.select(on, entry.bsdf.emission_weight(si, on), result)
    return result


def light_weight(entries: list[LayeredEmitter], scene: Any, si: Any, ds: Any, active: Any) -> Any:
    """The emission weight of light samples ``ds`` taken from ``si``: at the light point the ray from ``si`` along
    ``ds.d`` reaches, seen from ``si`` (1 for other emitters and where the ray finds no listed shape)."""
    import mitsuba as mi

    sampled = mi.Bool(False)
    for entry in entries:
        sampled |= ds.emitter == mi.EmitterPtr(entry.emitter)
    active = active & sampled
    hit = scene.ray_intersect(si.spawn_ray(ds.d), active)
    return weight(entries, hit, active & hit.is_valid())
