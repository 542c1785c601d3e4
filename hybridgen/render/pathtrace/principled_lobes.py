"""Microfacet and Fresnel terms of hybridgen's Principled BSDF (Dr.Jit, the active Mitsuba variant).

Directions are unit vectors in the local shading frame (z = the shading normal, x = the anisotropy tangent) with
the view direction ``wi`` in the upper hemisphere (the BSDF mirrors back-side hits first). Values follow the
conventions Blender 4.2's Cycles uses for its GGX closures:

- GGX (Trowbridge-Reitz) normal distribution with alphas (alpha_x, alpha_y), height-correlated Smith
  shadowing-masking G2 = 1 / (1 + Lambda(wi) + Lambda(wo)) (Heitz 2014);
- sampling of visible normals (Heitz 2018), so a reflection's pdf is D G1(wi) / (4 cos_i);
- "BSDF x cosine" values (what Mitsuba's ``eval`` returns): F D G2 / (4 cos_i) for reflection and
  F D G2 |h.wi| |h.wo| eta^2 / (cos_i (h.wi + eta h.wo)^2) for refraction, without a radiance 1/eta^2 factor
  (Cycles has none: a path entering and leaving a solid is the same either way);
- the multiple-scattering compensation of Kulla & Conty 2017 in the form Cycles applies it: the lobe times
  1 + F_ms (1 - E) / E with E the lobe's Fresnel-1 albedo from the view direction and
  F_ms = F_ss E_avg / (1 - F_ss (1 - E_avg)) (:func:`energy_factor`).
"""
from __future__ import annotations

from typing import Any

import drjit as dr
import mitsuba as mi

MIN_ALPHA = 1e-4
"""Smallest GGX alpha the lobes use (roughness 0.01): smoother surfaces stay glossy lobes with finite values."""


def ggx_d(h: Any, ax: Any, ay: Any) -> Any:
    """GGX normal distribution (sr^-1, per projected area) of the local half vector ``h``."""
    sx, sy = h.x / ax, h.y / ay
    length = sx * sx + sy * sy + h.z * h.z
    return dr.select(h.z > 0.0, dr.rcp(dr.pi * ax * ay * length * length), 0.0)


def ggx_lambda(v: Any, ax: Any, ay: Any) -> Any:
    """Smith Lambda of GGX for the local direction ``v`` (either hemisphere)."""
    z2 = dr.maximum(v.z * v.z, 1e-20)
    t = (dr.square(ax * v.x) + dr.square(ay * v.y)) / z2
    return 0.5 * (dr.sqrt(1.0 + t) - 1.0)


def sample_visible_normal(wi: Any, ax: Any, ay: Any, u: Any) -> Any:
    """A GGX normal drawn with the density of normals visible from ``wi`` (Heitz 2018), for u in [0, 1)^2."""
    v = dr.normalize(mi.Vector3f(ax * wi.x, ay * wi.y, wi.z))
    lensq = v.x * v.x + v.y * v.y
    t1 = dr.select(lensq > 1e-7, mi.Vector3f(-v.y, v.x, 0.0) * dr.rsqrt(dr.maximum(lensq, 1e-7)),
                   mi.Vector3f(1.0, 0.0, 0.0))
    t2 = dr.cross(v, t1)
    r, phi = dr.sqrt(u.x), dr.two_pi * u.y
    p1, p2 = r * dr.cos(phi), r * dr.sin(phi)
    s = 0.5 * (1.0 + v.z)
    p2 = (1.0 - s) * dr.safe_sqrt(1.0 - p1 * p1) + s * p2
    n = p1 * t1 + p2 * t2 + dr.safe_sqrt(1.0 - p1 * p1 - p2 * p2) * v
    return dr.normalize(mi.Vector3f(ax * n.x, ay * n.y, dr.maximum(n.z, 1e-7)))


def fresnel_dielectric(cos_i: Any, eta: Any) -> tuple[Any, Any]:
    """Unpolarized Fresnel reflectance for |cos_i| and relative IOR ``eta`` (transmitted / incident side), and
    the cosine of the refracted direction (0 at total internal reflection, where the reflectance is 1)."""
    c = dr.abs(cos_i)
    g2 = eta * eta - 1.0 + c * c
    g = dr.safe_sqrt(g2)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    reflectance = dr.select(g2 > 0.0, 0.5 * a * a * (1.0 + b * b), 1.0)
    return reflectance, dr.select(g2 > 0.0, g / eta, 0.0)


def f0_from_ior(eta: Any) -> Any:
    """Normal-incidence reflectance ((eta - 1) / (eta + 1))^2."""
    return dr.square((eta - 1.0) / (eta + 1.0))


def ior_from_f0(f0: Any) -> Any:
    """The IOR > 1 with normal-incidence reflectance ``f0`` (clamped to 0..0.99)."""
    root = dr.sqrt(dr.clip(f0, 0.0, 0.99))
    return (1.0 + root) / (1.0 - root)


def fresnel_remapped(cos_i: Any, eta: Any, f0: Any) -> Any:
    """Blender's dielectric Fresnel with a chosen F0 (Principled specular and transmission): the real curve's
    position between its own F0 and 1, s = (F(cos_i) - F0(eta)) / (1 - F0(eta)), mapped to f0 + (1 - f0) s."""
    real, _ = fresnel_dielectric(cos_i, eta)
    real_f0 = f0_from_ior(eta)
    s = dr.clip((real - real_f0) / dr.maximum(1.0 - real_f0, 1e-6), 0.0, 1.0)
    return dr.lerp(f0, 1.0, s)


F82_COS = 1.0 / 7.0
"""The cosine (about 82 degrees) at which the F82 tint sets a metal's reflectance relative to Schlick's."""


def f82_b(f0: Any, tint: Any) -> Any:
    """The coefficient b of F(mu) = Schlick(f0, mu) - b mu (1 - mu)^6 with F(1/7) = tint Schlick(f0, 1/7)
    (Hoffman's F82 tint, "Generalization of Adobe's Fresnel model")."""
    one_minus = 1.0 - F82_COS
    schlick = dr.lerp(f0, 1.0, one_minus ** 5)
    return schlick * (1.0 - tint) / (F82_COS * one_minus ** 6)


def fresnel_f82(mu: Any, f0: Any, b: Any) -> Any:
    """F82-tint metal reflectance at cosine ``mu`` (per channel, clamped to 0..1)."""
    m = dr.clip(1.0 - mu, 0.0, 1.0)
    m5 = dr.square(dr.square(m)) * m
    return dr.clip(dr.lerp(f0, 1.0, m5) - b * mu * m5 * m, 0.0, 1.0)


def f82_average(f0: Any, b: Any) -> Any:
    """2 int F82(mu) mu dmu = f0 + (1 - f0) / 21 - b / 126 (exact for the unclamped curve)."""
    return dr.lerp(f0, 1.0, 1.0 / 21.0) - b / 126.0


def energy_factor(e: Any, e_avg: Any, f_ss: Any) -> Any:
    """Multiple-scattering factor 1 + F_ms (1 - E) / E of a lobe with Fresnel-1 albedo ``e`` (from the view
    direction), average ``e_avg`` and cosine-averaged single-scattering Fresnel ``f_ss`` (a color)."""
    e = dr.maximum(e, 1e-4)
    f_ms = f_ss * e_avg / dr.maximum(1.0 - f_ss * (1.0 - e_avg), 1e-6)
    return 1.0 + f_ms * (1.0 - e) / e


def reflection(wi: Any, wo: Any, ax: Any, ay: Any) -> tuple[Any, Any, Any]:
    """GGX reflection without Fresnel: (D G2 / (4 cos_i), its visible-normal pdf, cos(h, wi)); zero where
    ``wo`` is below the surface."""
    valid = (wo.z > 0.0) & (wi.z > 0.0)
    h = dr.normalize(wi + wo)
    d = ggx_d(h, ax, ay)
    li, lo = ggx_lambda(wi, ax, ay), ggx_lambda(wo, ax, ay)
    common = d / (4.0 * dr.maximum(wi.z, 1e-7))
    value = dr.select(valid, common / (1.0 + li + lo), 0.0)
    pdf = dr.select(valid, common / (1.0 + li), 0.0)
    return value, pdf, dr.dot(h, wi)


def refraction(wi: Any, wo: Any, alpha: Any, eta: Any, every_pair: bool = False) -> tuple[Any, Any, Any]:
    """Isotropic GGX refraction into relative IOR ``eta`` without Fresnel: (D G2 |h.wi| |h.wo| eta^2 /
    (cos_i (h.wi + eta h.wo)^2), its visible-normal pdf, cos(h, wi)); zero unless ``wo`` is below.

    ``every_pair`` False: only pairs some microfacet refracts into each other (h up, h.wi > 0 > h.wo) have a value.
    True: Cycles 4.2's evaluation, which skips that test (its "check if the refraction configuration is valid"
    TODO) and values every pair with ``wo`` below by the same formula, h folded into the upper hemisphere (its D
    depends on cos^2). Sampling never draws those pairs; they are reached by light samples only, so a rough glass
    lit by small lights is brighter than the physical one (docs/principled_bsdf.md, "Refraction pairs")."""
    raw = wi + eta * wo  # the generalized half vector (Walter et al. 2007) points up for physical refractions
    h = dr.normalize(dr.select(eta > 1.0, -raw, raw))
    if every_pair:
        h = dr.select(h.z < 0.0, -h, h)
    cos_hi, cos_ho = dr.dot(h, wi), dr.dot(h, wo)
    valid = (wo.z < 0.0) & (wi.z > 0.0)
    if not every_pair:
        valid &= (h.z > 0.0) & (cos_hi > 0.0) & (cos_ho < 0.0)
    d = ggx_d(h, alpha, alpha)
    li, lo = ggx_lambda(wi, alpha, alpha), ggx_lambda(wo, alpha, alpha)
    jacobian = eta * eta * dr.abs(cos_hi * cos_ho) / dr.maximum(dr.square(cos_hi + eta * cos_ho), 1e-12)
    common = d * jacobian / dr.maximum(wi.z, 1e-7)
    value = dr.select(valid, common / (1.0 + li + lo), 0.0)
    pdf = dr.select(valid, common / (1.0 + li), 0.0)
    return value, pdf, cos_hi


def refract(wi: Any, h: Any, cos_t: Any, eta: Any) -> Any:
    """Direction refracted through the microfacet ``h`` into relative IOR ``eta``, given |cos| of the refracted
    angle ``cos_t`` (from :func:`fresnel_dielectric`)."""
    inv = dr.rcp(eta)
    return (inv * dr.dot(h, wi) - cos_t) * h - inv * wi
