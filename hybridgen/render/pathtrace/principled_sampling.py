"""Lobe choice and direction drawing of hybridgen's Principled BSDF, shared by its single-frame form
(:class:`~.principled_bsdf.PrincipledBSDF`) and its frame-per-layer form (:mod:`.principled_layered`).

One uniform number ``sample1`` picks a lobe by the cumulative sampling shares of :class:`~.principled_layers.Layers`
(coat, metal, glass, dielectric specular, diffuse, sheen; Cycles' sample weights plus a floor), then ``sample2``
draws a direction from it: visible GGX normals for the glossy lobes (the glass reflecting or refracting by its
Fresnel, reusing the rescaled ``sample1``), a cosine lobe for the diffuse base. Directions are local to the
layer's frame (z its normal, ``wi.z`` > 0). Dr.Jit values of the active variant.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import drjit as dr
import mitsuba as mi

from . import principled_layers as layers_mod
from . import principled_lobes as lobes


@dataclass
class Choice:
    """The lobe ``sample1`` picks: cumulative shares and one mask per lobe (sheen's is ``pick_sheen``, within
    ``pick_diffuse``: both are sampled as diffuse bounces, Cycles' label)."""

    sample1: Any
    c_metal: Any
    c_spec: Any
    pick_coat: Any
    pick_glass: Any
    pick_diffuse: Any
    pick_sheen: Any


def choose(lay: Any, sample1: Any, has_sheen: bool) -> Choice:
    """The lobe of ``lay`` (:class:`~.principled_layers.Layers`) that ``sample1`` in [0, 1) picks."""
    s = lay.shares
    c_coat, c_metal = s[0], s[0] + s[1]
    c_glass, c_spec = c_metal + s[2], c_metal + s[2] + s[3]
    pick_coat, pick_glass, pick_diffuse = sample1 < c_coat, (sample1 >= c_metal) & (sample1 < c_glass), \
        sample1 >= c_spec
    pick_sheen = sample1 >= c_spec + s[4] if has_sheen else None
    return Choice(sample1, c_metal, c_spec, pick_coat, pick_glass, pick_diffuse, pick_sheen)


def draw(lay: Any, wi: Any, choice: Choice, sample2: Any, alpha_x: Any, alpha_y: Any,
         has_transmission: bool) -> tuple[Any, Any]:
    """(local ``wo``, whether it refracts) for the chosen lobe: a GGX reflection with ``alpha_x`` / ``alpha_y``
    (or the glass's refraction), or the diffuse base's cosine lobe."""
    h = lobes.sample_visible_normal(wi, alpha_x, alpha_y, sample2)
    cos_hi = dr.dot(h, wi)
    wo = 2.0 * cos_hi * h - wi
    refract = mi.Bool(False)
    if has_transmission:
        p_reflect, _, _ = layers_mod.glass_reflect_probability(lay, cos_hi)
        u = (choice.sample1 - choice.c_metal) / dr.maximum(lay.shares[2], 1e-20)
        _, cos_t = lobes.fresnel_dielectric(cos_hi, lay.eta_glass)
        refract = choice.pick_glass & (u >= p_reflect) & (cos_t > 0.0)
        wo = dr.select(refract, lobes.refract(wi, h, cos_t, lay.eta_glass), wo)
    return dr.select(choice.pick_diffuse, mi.warp.square_to_cosine_hemisphere(sample2), wo), refract


def sample_record(wo: Any, pdf: Any, ok: Any, refract: Any, choice: Choice, lay: Any) -> Any:
    """The ``BSDFSample3f`` of a drawn direction ``wo`` (shading-frame coordinates): pdf (0 where not ``ok``),
    relative IOR, the sampled lobe's flags and component (0 diffuse, 1 glossy reflection, 2 transmission)."""
    flags = mi.BSDFFlags
    bs = dr.zeros(mi.BSDFSample3f)
    bs.wo = wo
    bs.pdf = dr.select(ok, pdf, 0.0)
    bs.eta = dr.select(refract, lay.eta_glass, 1.0)
    bs.sampled_type = dr.select(choice.pick_diffuse, mi.UInt32(+flags.DiffuseReflection),
                                dr.select(refract, mi.UInt32(+flags.GlossyTransmission),
                                          mi.UInt32(+flags.GlossyReflection)))
    bs.sampled_component = dr.select(choice.pick_diffuse, mi.UInt32(0),
                                     dr.select(refract, mi.UInt32(2), mi.UInt32(1)))
    return bs
