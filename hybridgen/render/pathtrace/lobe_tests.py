"""Per-lane tests of a path vertex's BSDF lobes for :mod:`hybridgen.render.pathtrace.clamped_path`: singular
surfaces as Cycles treats them (no next-event estimation; see that module's docstring) and refraction."""
from __future__ import annotations

from typing import Any

import numpy as np

from ...scene.material import Material

SINGULAR_ROUGHNESS = 2e-10 ** 0.25
"""Principled roughness (Blender's; alpha = roughness^2) at or below which a lobe is singular, as in Cycles:
``alpha_x alpha_y <= BSDF_ROUGHNESS_SQ_THRESH = 2e-10``, i.e. roughness <= 0.00376."""


def is_singular(bsdf: Any, si: Any, active: Any = True) -> Any:
    """Per lane: ``bsdf`` (a Mitsuba BSDF pointer array) is a principled BSDF (also inside ``twosided``) with
    no diffuse lobe (``metallic`` or ``spec_trans`` 1: metal, glass) and a ``roughness`` of at most
    :data:`SINGULAR_ROUGHNESS` at ``si``, after the glossy filter's floor in ``si.time``. A principled BSDF with
    a diffuse lobe keeps next-event estimation (Cycles would evaluate its diffuse closure only; Mitsuba's
    principled evaluates all lobes together); other BSDFs (diffuse, blends of specular maps) are never
    singular here."""
    principled = bsdf.has_attribute("roughness", active) & bsdf.has_attribute("metallic", active)
    no_diffuse = (bsdf.eval_attribute_1("metallic", si, active) >= 1.0) | \
        (bsdf.eval_attribute_1("spec_trans", si, active) >= 1.0)
    return principled & no_diffuse & (bsdf.eval_attribute_1("roughness", si, active) <= SINGULAR_ROUGHNESS)


def may_be_singular(material: Material) -> bool:
    """Whether any point of a surface with ``material`` can be singular (:func:`is_singular`: no diffuse lobe,
    roughness at most :data:`SINGULAR_ROUGHNESS`): fully metallic or transmissive somewhere (a value of 1 or a
    metallic map) and that smooth somewhere (a roughness at or below the threshold, or a roughness map). False
    guarantees that :func:`is_singular` is false on every lane the material's BSDF is hit; True may be
    conservative. Values are compared as the BSDF holds and the kernel compares them, in float32 (1 - 1e-9 is 1
    there)."""
    if material.mixes:  # a mix with such a material is refused (render/pathtrace/material_mixes.py)
        return False
    f32 = np.float32
    metal_or_glass = f32(material.metallic) >= 1 or material.metallic_texture is not None or \
        f32(material.transmission) >= 1
    smooth = f32(material.roughness) <= f32(SINGULAR_ROUGHNESS) or material.roughness_texture is not None
    return bool(metal_or_glass and smooth)


def transmission(flags: Any) -> Any:
    """Per lane: Mitsuba BSDF ``flags`` (of a BSDF, or of a sample's lobe) include a glossy or sharp transmission
    lobe - a refraction, which Cycles' transmission bounces count."""
    import mitsuba as mi

    return mi.has_flag(flags, mi.BSDFFlags.GlossyTransmission) | mi.has_flag(flags, mi.BSDFFlags.DeltaTransmission)


def refracts(bsdf: Any, si: Any, wo: Any) -> Any:
    """Per lane: ``bsdf`` has a glossy or sharp transmission lobe (principled ``spec_trans`` > 0) and the local
    direction ``wo`` lies on the other side of the surface than ``si.wi``, i.e. light along ``wo`` reaches
    ``si.wi`` only by refraction."""
    import mitsuba as mi

    return transmission(bsdf.flags()) & (mi.Frame3f.cos_theta(si.wi) * mi.Frame3f.cos_theta(wo) < 0.0)
