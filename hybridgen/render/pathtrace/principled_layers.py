"""The layer weights of Blender 4.2's Principled BSDF at one shading point, for one view direction.

Blender stacks its closures top down and lets each layer darken what lies below it by the layer's estimated
albedo from the view direction ``wi`` (Cycles' ``closure_layering_weight``); metal and transmission instead mix
by their weights. With W the weight still left for the layers below (a color, 1 at the top):

0. sheen (``sheen_weight`` > 0): the microfiber sheen lobe (:mod:`.principled_sheen`) with albedo
   A_sheen = sheen_weight x sheen_tint x R(mu, sheen_roughness); W *= 1 - max_channel(A_sheen);
1. coat (``coat_weight`` > 0): a dielectric GGX reflection with the coat's own IOR and roughness, weight
   ``coat_weight`` W; then W *= 1 - coat_weight A_coat and, for a coat tint, W *= lerp(1, tint^(1/cos_t),
   coat_weight) with cos_t the view direction refracted into the coat (Beer's law over the coat's thickness);
2. metal: weight ``metallic`` W, reflectance F82 tint (F0 = base color, the 82-degree tint = ``specular_tint``);
   W *= 1 - metallic;
3. transmission: a rough dielectric (isotropic) with the IOR (1/IOR from the back side), reflection F and
   refraction (1 - F) sqrt(base color), weight ``transmission`` W; W *= 1 - transmission;
4. the dielectric specular layer: GGX reflection with F0 = F0(IOR) x 2 ``specular`` (Specular IOR Level,
   0.5 = the IOR's own F0) tinted by ``specular_tint``, weight W; W *= 1 - max_channel(A_spec);
5. Lambertian diffuse: base color x W / pi; with subsurface weight w, (1 - w) base color + w min(base color, 1)
   (Cycles' BSSRDF closure falls back to this diffuse lobe with the clamped base color wherever it does no
   random walk: radius x scale below 1e-8 per channel, and after a diffuse bounce; hybridgen never walks).

Every GGX lobe is energy compensated (:func:`principled_lobes.energy_factor`). A layer's albedo A is Cycles'
estimate: (E + F_ms (1 - E)) (F0 + (1 - F0) s) with s from the ``schlick_s`` table (the Fresnel-weighted
fraction of the lobe's energy). Random-walk subsurface scattering is not modelled (see docs/principled_bsdf.md).
Per-lane quantities are Dr.Jit values of the active variant; inputs are read by
:class:`~hybridgen.render.pathtrace.principled_bsdf.PrincipledBSDF`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import drjit as dr
import mitsuba as mi

from . import principled_lobes as lobes
from . import principled_sheen as sheen
from . import principled_tables as tables

MIN_LOBE_SHARE = 0.05
"""Share of the total sampling weight every present lobe gets on top of its albedo share (keeps a BSDF-sampling
technique for MIS on highlights of dark surfaces)."""


@dataclass
class Inputs:
    """The Principled inputs at a point (Blender's names in the comments); per-lane Dr.Jit values except flags."""

    base: Any  # Base Color (linear RGB, >= 0)
    rough: Any  # Roughness 0..1
    metallic: Any  # Metallic 0..1
    level: Any  # Specular IOR Level >= 0
    ior: Any  # IOR
    spec_tint: Any  # Specular Tint (RGB)
    transmission: Any  # Transmission Weight 0..1
    aspect: Any  # sqrt(1 - 0.9 Anisotropic)
    coat: Any  # Coat Weight
    coat_rough: Any  # Coat Roughness
    coat_ior: Any  # Coat IOR
    coat_tint: Any  # Coat Tint (RGB)
    has_coat: bool
    has_transmission: bool
    has_coat_tint: bool
    sheen: Any = 0.0  # Sheen Weight
    sheen_rough: Any = 0.5  # Sheen Roughness
    sheen_tint: Any = 1.0  # Sheen Tint (RGB)
    subsurface: Any = 0.0  # Subsurface Weight 0..1
    has_sheen: bool = False
    has_subsurface: bool = False
    every_refraction_pair: bool = True  # Cycles' refraction evaluation (principled_lobes.refraction)


@dataclass
class Layers:
    """Lobe weights (colors, energy compensation included) and parameters for one view direction."""

    ax: Any
    ay: Any
    alpha_glass: Any
    alpha_coat: Any
    coat_w: Any
    coat_ior: Any
    metal_w: Any
    f0_metal: Any
    b_metal: Any
    glass_w: Any
    eta_glass: Any
    f0_glass: Any
    tint_glass: Any
    spec_w: Any
    eta_spec: Any
    f0_spec: Any
    diffuse_w: Any
    shares: list[Any]  # sampling probabilities: coat, metal, glass, spec, diffuse[, sheen] (sum 1 where anything
    # reflects)
    sheen_w: Any = None  # the sheen lobe's albedo (color), with its LTC (a, b) and frame (cos, sin)
    sheen_a: Any = None
    sheen_b: Any = None
    sheen_frame: Any = None
    every_refraction_pair: bool = True  # see Inputs


def _average(color: Any) -> Any:
    return (color[0] + color[1] + color[2]) * (1.0 / 3.0)


def _max(color: Any) -> Any:
    return dr.maximum(dr.maximum(color[0], color[1]), color[2])


def _reflective_layer(rough: Any, mu: Any, eta: Any, f0: Any) -> tuple[Any, Any]:
    """(energy factor, estimated albedo) of an energy-compensated dielectric GGX reflection whose Fresnel is
    Blender's remapped curve from ``f0`` (a color) to 1 at relative IOR ``eta``."""
    e, e_avg = tables.ggx_energy(rough, mu)
    real_f0 = lobes.f0_from_ior(eta)
    s_avg = dr.clip((tables.fresnel_average(eta) - real_f0) / dr.maximum(1.0 - real_f0, 1e-6), 0.0, 1.0)
    factor = lobes.energy_factor(e, e_avg, dr.lerp(f0, 1.0, s_avg))
    estimate = dr.lerp(f0, 1.0, tables.fresnel_interpolation(rough, mu, eta))
    return factor, factor * e * estimate


def _sheen_layer(inp: Inputs, mu: Any) -> tuple[Any, Any, Any, Any]:
    """(LTC a, b, the sheen lobe's albedo (color), the weight it leaves below: 1 - its largest channel) for the
    view cosine ``mu`` to the sheen's normal."""
    a, b, albedo = tables.sheen_ltc(inp.sheen_rough, mu)
    sheen_w = inp.sheen * inp.sheen_tint * albedo
    return a, b, sheen_w, dr.clip(1.0 - _max(sheen_w), 0.0, 1.0)


def _coat_layer(inp: Inputs, mu: Any, weight: Any) -> tuple[Any, Any, Any, Any]:
    """(GGX alpha, lobe weight, sampling share, the weight left below) of the coat for the view cosine ``mu`` to
    the coat's normal, under ``weight`` (what the sheen left)."""
    alpha_coat = dr.maximum(dr.square(inp.coat_rough), lobes.MIN_ALPHA)
    coat_f0 = mi.Color3f(lobes.f0_from_ior(inp.coat_ior))
    factor, albedo = _reflective_layer(inp.coat_rough, mu, inp.coat_ior, coat_f0)
    coat_w = inp.coat * factor
    share_coat = inp.coat * _average(albedo)
    if inp.has_sheen:  # under the sheen (a gray weight: the sheen takes its albedo's largest channel)
        coat_w, share_coat = coat_w * weight, share_coat * _average(weight)
    weight = weight * dr.clip(1.0 - inp.coat * _max(albedo), 0.0, 1.0)
    if inp.has_coat_tint:
        weight = weight * _coat_absorption(inp, mu)
    return alpha_coat, coat_w, share_coat, weight


def _coat_absorption(inp: Inputs, mu: Any) -> Any:
    """The coat tint's transmittance (a color) for the view cosine ``mu``: Beer's law over the coat's unit
    thickness along the view refracted into it, lerp(1, tint^(1 / cos_t), Coat Weight)."""
    cos_t = dr.safe_sqrt(1.0 - (1.0 - mu * mu) / dr.square(inp.coat_ior))
    absorbed = dr.power(inp.coat_tint, dr.rcp(dr.maximum(cos_t, 1e-4)))
    return dr.lerp(mi.Color3f(1.0), absorbed, inp.coat)


def emission_weight(inp: Inputs, wi_sheen: Any, wi_coat: Any, layers: bool = True) -> Any:
    """What the sheen and coat leave of the emission (a color; Cycles' ``emission_setup`` under the layer weight
    after sheen and coat) for the local view directions ``wi_sheen`` / ``wi_coat`` in those layers' frames.
    ``layers`` False: only the coat tint's absorption - what Cycles applies where it sets up no closures (light
    samples, a path's last vertex), the tint being applied outside the coat closure's allocation."""
    weight = mi.Color3f(1.0)
    if not layers:
        return weight * _coat_absorption(inp, dr.maximum(wi_coat.z, 1e-6)) if inp.has_coat_tint else weight
    if inp.has_sheen:
        weight = weight * _sheen_layer(inp, dr.maximum(wi_sheen.z, 1e-6))[3]
    if inp.has_coat:
        weight = _coat_layer(inp, dr.maximum(wi_coat.z, 1e-6), weight)[3]
    return weight


def layers(inp: Inputs, wi: Any, backfacing: Any, wi_coat: Any = None, wi_sheen: Any = None) -> Layers:
    """The layer weights for the local view direction ``wi`` (cosine to the (flipped) normal: its z > 0);
    ``wi_coat`` / ``wi_sheen``: the view in the coat's / sheen's own frame where their normals differ from the
    base's (:mod:`.principled_frames`), else ``wi``."""
    weight = mi.Color3f(1.0)
    mu = dr.maximum(wi.z, 1e-6)
    sheen_w, sheen_ab, share_sheen = None, (None, None), mi.Float(0.0)
    if inp.has_sheen:
        a, b, sheen_w, leave = _sheen_layer(inp, mu if wi_sheen is None else dr.maximum(wi_sheen.z, 1e-6))
        weight = weight * leave
        sheen_ab, share_sheen = (a, b), _average(sheen_w)
    alpha = dr.maximum(dr.square(inp.rough), lobes.MIN_ALPHA)
    ax, ay = dr.minimum(alpha / inp.aspect, 1.0), alpha * inp.aspect
    coat_w, alpha_coat, share_coat = mi.Color3f(0.0), mi.Float(lobes.MIN_ALPHA), mi.Float(0.0)
    if inp.has_coat:
        alpha_coat, coat_w, share_coat, weight = _coat_layer(
            inp, mu if wi_coat is None else dr.maximum(wi_coat.z, 1e-6), weight)
    f0_metal = dr.clip(inp.base, 0.0, 1.0)
    b_metal = lobes.f82_b(f0_metal, dr.minimum(inp.spec_tint, 1.0))
    e, e_avg = tables.ggx_energy(inp.rough, mu)
    metal_w = weight * inp.metallic * lobes.energy_factor(e, e_avg, lobes.f82_average(f0_metal, b_metal))
    share_metal = _average(metal_w * e * lobes.f82_average(f0_metal, b_metal))
    weight = weight * (1.0 - inp.metallic)
    glass_w, share_glass = mi.Color3f(0.0), mi.Float(0.0)
    eta_glass = dr.select(backfacing, dr.rcp(inp.ior), inp.ior)
    f0_glass = dr.clip(lobes.f0_from_ior(inp.ior) * inp.spec_tint, 0.0, 1.0)
    tint_glass = dr.sqrt(dr.clip(inp.base, 0.0, 1.0))
    if inp.has_transmission:
        e_g, e_avg_g = tables.glass_energy(inp.rough, mu, eta_glass)
        glass_w = weight * inp.transmission * lobes.energy_factor(e_g, e_avg_g, tint_glass)
        f_mu = lobes.fresnel_remapped(mu, eta_glass, f0_glass)
        share_glass = _average(glass_w * e_g * (f_mu + (1.0 - f_mu) * tint_glass))
        weight = weight * (1.0 - inp.transmission)
    real_f0 = lobes.f0_from_ior(inp.ior)
    eta_spec = dr.select(inp.level == 0.5, inp.ior, lobes.ior_from_f0(real_f0 * 2.0 * inp.level))
    eta_spec = dr.select((inp.ior < 1.0) & (inp.level != 0.5), dr.rcp(eta_spec), eta_spec)
    has_spec = dr.abs(eta_spec - 1.0) > 1e-6
    f0_spec = dr.clip(lobes.f0_from_ior(eta_spec) * inp.spec_tint, 0.0, 1.0)
    factor, albedo = _reflective_layer(inp.rough, mu, eta_spec, f0_spec)
    spec_w = dr.select(has_spec, weight * factor, 0.0)
    share_spec = dr.select(has_spec, _average(weight * albedo), 0.0)
    weight = dr.select(has_spec, weight * dr.clip(1.0 - _max(albedo), 0.0, 1.0), weight)
    diffuse_w = weight * dr.maximum(inp.base, 0.0)
    if inp.has_subsurface:
        diffuse_w = weight * dr.lerp(dr.maximum(inp.base, 0.0), dr.clip(inp.base, 0.0, 1.0), inp.subsurface)
    raw = [share_coat, share_metal, share_glass, share_spec, _average(diffuse_w)]
    if inp.has_sheen:
        raw.append(share_sheen)
    total = raw[0] + raw[1] + raw[2] + raw[3] + raw[4]
    if inp.has_sheen:
        total = total + raw[5]
    floored = [dr.select(r > 0.0, r + MIN_LOBE_SHARE * total, 0.0) for r in raw]
    floored_sum = floored[0] + floored[1] + floored[2] + floored[3] + floored[4]
    if inp.has_sheen:
        floored_sum = floored_sum + floored[5]
    norm = dr.rcp(dr.maximum(floored_sum, 1e-20))
    return Layers(ax=ax, ay=ay, alpha_glass=alpha, alpha_coat=alpha_coat, coat_w=coat_w, coat_ior=inp.coat_ior,
                  metal_w=metal_w, f0_metal=f0_metal, b_metal=b_metal, glass_w=glass_w, eta_glass=eta_glass,
                  f0_glass=f0_glass, tint_glass=tint_glass, spec_w=spec_w, eta_spec=eta_spec, f0_spec=f0_spec,
                  diffuse_w=diffuse_w, shares=[f * norm for f in floored], sheen_w=sheen_w, sheen_a=sheen_ab[0],
                  sheen_b=sheen_ab[1],
                  sheen_frame=sheen.sheen_frame(wi if wi_sheen is None else wi_sheen) if inp.has_sheen else None,
                  every_refraction_pair=inp.every_refraction_pair)


def glass_reflect_probability(lay: Layers, cos_hi: Any) -> tuple[Any, Any, Any]:
    """(probability of reflecting, reflectance F, transmittance (1 - F) tint) of the glass at cos(h, wi)."""
    f = lobes.fresnel_remapped(cos_hi, lay.eta_glass, lay.f0_glass)
    t = (1.0 - f) * lay.tint_glass
    return _average(f) / dr.maximum(_average(f + t), 1e-20), f, t


def eval_pdf(lay: Layers, wi: Any, wo: Any, has_coat: bool, has_transmission: bool,
             has_sheen: bool = False, coat: tuple[Any, Any, Any] | None = None,
             sheen_dirs: tuple[Any, Any, Any] | None = None, base_ok: Any = None,
             diffuse_scale: Any = None) -> tuple[Any, Any]:
    """(BSDF x |cos(wo)| as RGB, pdf of :meth:`PrincipledBSDF.sample`) for local ``wi`` (upper) and ``wo``.

    ``coat`` / ``sheen_dirs``: (wi, wo, ok) in the coat's / sheen's own frame where it differs from the base's
    (:mod:`.principled_frames`; ``ok``: the layer's value counts there), ``base_ok`` likewise for the base's
    reflections (its refraction counts where it is false); ``diffuse_scale``: (diffuse lobe, sheen lobe) factors
    (Cycles' bump shadowing of diffuse closures); the pdf is the mixture's whatever the masks and factors."""
    refl, refl_pdf, cos_hi = lobes.reflection(wi, wo, lay.ax, lay.ay)
    value = lay.spec_w * lobes.fresnel_remapped(cos_hi, lay.eta_spec, lay.f0_spec) * refl
    value += lay.metal_w * lobes.fresnel_f82(cos_hi, lay.f0_metal, lay.b_metal) * refl
    pdf = (lay.shares[1] + lay.shares[3]) * refl_pdf
    upper = wo.z > 0.0
    diffuse = lay.diffuse_w * wo.z * dr.inv_pi
    value += dr.select(upper, diffuse if diffuse_scale is None else diffuse * diffuse_scale[0], 0.0)
    pdf += lay.shares[4] * dr.select(upper, wo.z * dr.inv_pi, 0.0)
    if has_transmission:
        g_refl, g_pdf, g_cos = lobes.reflection(wi, wo, lay.alpha_glass, lay.alpha_glass)
        p_reflect, f, _ = glass_reflect_probability(lay, g_cos)
        g_refr, t_pdf, t_cos = lobes.refraction(wi, wo, lay.alpha_glass, lay.eta_glass, lay.every_refraction_pair)
        p_reflect_t, _, t = glass_reflect_probability(lay, t_cos)
        if base_ok is None:
            glass = lay.glass_w * (f * g_refl + t * g_refr)
        else:  # a reflection on the viewer's side of the surface, a refraction on the other
            glass = lay.glass_w * dr.select(base_ok, f * g_refl, t * g_refr)
        glass_pdf = lay.shares[2] * (p_reflect * g_pdf + (1.0 - p_reflect_t) * t_pdf)
    if base_ok is not None:
        value = dr.select(base_ok, value, 0.0)
    if has_coat:
        wi_c, wo_c, ok_c = (wi, wo, None) if coat is None else coat
        c_refl, c_pdf, c_cos = lobes.reflection(wi_c, wo_c, lay.alpha_coat, lay.alpha_coat)
        coat_value = lay.coat_w * lobes.fresnel_dielectric(c_cos, lay.coat_ior)[0] * c_refl
        value += coat_value if ok_c is None else dr.select(ok_c, coat_value, 0.0)
        pdf += lay.shares[0] * c_pdf
    if has_transmission:
        value += glass
        pdf += glass_pdf
    if has_sheen:
        wo_s, ok_s = (wo, None) if sheen_dirs is None else sheen_dirs[1:]
        lobe = sheen.sheen_lobe(lay.sheen_a, lay.sheen_b, lay.sheen_frame, wo_s)
        sheen_value = lay.sheen_w * lobe if diffuse_scale is None else lay.sheen_w * lobe * diffuse_scale[1]
        value += sheen_value if ok_s is None else dr.select(ok_s, sheen_value, 0.0)
        pdf += lay.shares[5] * lobe
    return value, pdf
