"""One vertex of :mod:`hybridgen.render.pathtrace.clamped_path`'s paths: the body of its ``dr.while_loop``.

The loop state is spelled once, as :func:`path_vertex`'s parameters: :data:`LOOP_STATE` is read from its
signature, the integrator builds the initial state and reads the result by those names. The names are every
variable the loop reads or writes, sorted, as ``@dr.syntax`` derived them from the former ``while`` loop
(``diffuse_prev`` came later, for ``caustics_refractive``), so the traced kernels are the ones that loop traced; the
explicit loop only saves re-parsing the source in every process (~0.01 s CPU measured; most of the 0.15 s once
blamed on ``dr.syntax`` was Mitsuba's own AD integrators, see
:mod:`hybridgen.render.pathtrace.deferred_ad_integrators`).
"""
from __future__ import annotations

from typing import Any, Mapping

from . import glossy_filter, layered_emission, transparent_shadows, world_guide
from .lobe_tests import is_singular, refracts, transmission


def path_vertex(active: Any, bsdf_ctx: Any, bsdf_delta_prev: Any, bsdf_pdf_prev: Any, depth: Any, diffuse_prev: Any,
                eta: Any, filter_glossy: Any, guide: Any, guided_prev: Any, hidden: Any, last_segment: Any,
                max_depth: Any, max_diffuse: Any, max_glossy: Any, max_transmission: Any, min_ray_pdf: Any,
                mis_weight: Any, n_diffuse: Any, n_glossy: Any, n_transmission: Any, n_transparent: Any,
                radiance: Any, ray: Any, rr_depth: Any, sampler: Any, scene: Any, self: Any, si_prev: Any,
                throughput: Any, transparent: Any, world_radiance: Any) -> tuple[Any, ...]:
    """One path vertex (the ``dr.while_loop`` body): takes the loop state as its parameters and returns it, in
    :data:`LOOP_STATE` order. Python-level settings are read from the integrator (``self``) while tracing."""
    import drjit as dr
    import mitsuba as mi

    has_hidden = len(self.hidden_shapes) > 0
    no_refractive_caustics = not self.caustics_refractive

    si = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0, active=active)
    if filter_glossy > 0:  # roughness floor for the wrapped principled roughness (glossy_filter.py)
        si.time = glossy_filter.roughness_floor(filter_glossy, min_ray_pdf)
    bsdf = si.bsdf(ray)

    # Emission found by the previous BSDF sample (or seen directly), MIS-weighted against NEE.
    ds = mi.DirectionSample3f(scene, si=si, ref=si_prev)
    em_pdf = scene.pdf_emitter_direction(si_prev, ds, ~bsdf_delta_prev)
    if guide is not None:  # a world hit: the previous vertex's guided world sample could find it too
        em_pdf = dr.select(guided_prev & ~si.is_valid(),
                           world_guide.pdf(guide, si_prev.p, ray.d, active), em_pdf)
    mis_bsdf = dr.select(depth == 0, 1.0, mis_weight(bsdf_pdf_prev, em_pdf))
    emitted = throughput * mis_bsdf * ds.emitter.eval(si, active)
    if self.layered_emitters:  # emission under a coat or sheen: what they leave towards this view, where the
        # path goes on (Cycles evaluates no layers at a path's last vertex nor for light samples)
        emitted *= layered_emission.weight(self.layered_emitters, si, active,
                                           (depth + 1 < max_depth) & ~last_segment)
    if has_hidden:  # camera rays see such an emitter's BSDF only, other rays its emission only
        hidden = self._camera_hidden(si)
        emitted = dr.select(hidden & (depth == 0), 0.0, emitted)
    radiance += self._clamped(emitted, depth >= 2)

    active_next = active & (depth + 1 < max_depth) & si.is_valid() & ~last_segment
    if has_hidden:
        active_next &= ~(hidden & (depth > 0))

    # Singular surfaces (roughness <= SINGULAR_ROUGHNESS after the glossy filter's floor): no NEE.
    singular = is_singular(bsdf, si, active) if self.singular_surfaces else mi.Bool(False)

    # Next-event estimation: one emitter sample, MIS-weighted against BSDF sampling.
    active_em = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth) & ~singular
    ds_em, em_weight = scene.sample_emitter_direction(si, sampler.next_2d(), False, active_em)
    active_em &= ds_em.pdf != 0.0
    wo = si.to_local(ds_em.d)
    if no_refractive_caustics:  # no light through a refracting surface reached by a diffuse bounce
        active_em &= ~(diffuse_prev & refracts(bsdf, si, wo))
    bsdf_val, bsdf_pdf = bsdf.eval_pdf(bsdf_ctx, si, wo, active_em)
    # The shadow ray only where the light sample can contribute (module docstring: same values)
    needs_shadow_ray = active_em & (dr.max(mi.unpolarized_spectrum(bsdf_val)) > 0) & \
        (dr.max(mi.unpolarized_spectrum(em_weight)) > 0)
    if transparent:
        em_weight *= transparent_shadows.shadow_transmittance(scene, si, ds_em, needs_shadow_ray)
    else:
        blocked = scene.ray_test(si.spawn_ray_to(ds_em.p), needs_shadow_ray)
        em_weight = dr.select(blocked, 0.0, em_weight)
    if self.layered_emitters and layered_emission.tinted(self.layered_emitters):  # a coat tint's absorption
        em_weight *= layered_emission.light_weight(self.layered_emitters, scene, si, ds_em, needs_shadow_ray)
    mis_em = dr.select(ds_em.delta, 1.0, mis_weight(ds_em.pdf, bsdf_pdf))
    lit = dr.select(active_em, throughput * bsdf_val * em_weight * mis_em, 0.0)
    radiance += self._clamped(lit, depth >= 1)
    if guide is not None:  # one more light sample: the world, in directions learned for this place
        active_world = active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth) & ~singular
        d_world, pdf_world = world_guide.sample(guide, si.p, sampler.next_1d(), sampler.next_2d(),
                                                active_world)
        active_world &= ~scene.ray_test(si.spawn_ray(d_world), active_world)
        wo_world = si.to_local(d_world)
        if no_refractive_caustics:
            active_world &= ~(diffuse_prev & refracts(bsdf, si, wo_world))
        val_world, pdf_bsdf_world = bsdf.eval_pdf(bsdf_ctx, si, wo_world, active_world)
        sky = throughput * val_world * world_radiance * \
            (mis_weight(pdf_world, pdf_bsdf_world) / dr.maximum(pdf_world, 1e-20))
        radiance += self._clamped(dr.select(active_world, sky, 0.0), depth >= 1)
        guided_prev = mi.Bool(active_next & mi.has_flag(bsdf.flags(), mi.BSDFFlags.Smooth) & ~singular)

    # BSDF sampling: the next segment.
    bsdf_sample, bsdf_weight = bsdf.sample(bsdf_ctx, si, sampler.next_1d(), sampler.next_2d(),
                                           active_next)
    sampled = bsdf_sample.sampled_type
    transmits = transmission(sampled)
    glossy = mi.has_flag(sampled, mi.BSDFFlags.GlossyReflection) | \
        mi.has_flag(sampled, mi.BSDFFlags.DeltaReflection)
    diffuse = mi.has_flag(sampled, mi.BSDFFlags.Diffuse)
    n_diffuse[active_next & diffuse] += 1
    n_glossy[active_next & glossy] += 1
    n_transmission[active_next & transmits] += 1
    last_segment = ((n_diffuse > max_diffuse) | (n_glossy > max_glossy)
                    | (n_transmission > max_transmission))
    if no_refractive_caustics:  # a refraction sampled there ends the path, finding nothing
        active_next &= ~(diffuse_prev & transmits)
    ray = si.spawn_ray(si.to_world(bsdf_sample.wo))
    throughput *= bsdf_weight
    eta *= bsdf_sample.eta
    # a null pass (through a transparent texel) keeps the last real vertex's MIS state and bounces
    null_pass = mi.has_flag(sampled, mi.BSDFFlags.Null) & transparent & si.is_valid()
    n_transparent[null_pass] += 1
    last_segment |= n_transparent > transparent_shadows.MAX_TRANSPARENT
    si_prev = dr.select(null_pass, si_prev, si)
    diffuse_prev = dr.select(null_pass, diffuse_prev, diffuse)
    bsdf_pdf_prev = dr.select(null_pass, bsdf_pdf_prev, bsdf_sample.pdf)
    bsdf_delta_prev = dr.select(null_pass, bsdf_delta_prev,
                                mi.has_flag(bsdf_sample.sampled_type, mi.BSDFFlags.Delta) | singular)
    depth[si.is_valid() & ~null_pass] += 1
    if filter_glossy > 0:
        rough = active_next & ~null_pass & ~mi.has_flag(sampled, mi.BSDFFlags.Delta)
        min_ray_pdf = dr.select(rough, dr.minimum(min_ray_pdf, bsdf_sample.pdf), min_ray_pdf)

    # Russian roulette from rr_depth on (survivors are reweighted: unbiased), with Cycles' gentler
    # continuation probability sqrt(max throughput) (Mitsuba's path: min(throughput eta^2, 0.95)).
    throughput_max = dr.max(mi.unpolarized_spectrum(throughput))
    rr_prob = dr.minimum(dr.sqrt(throughput_max), 1.0)
    rr_active = depth >= rr_depth
    throughput[rr_active] *= dr.rcp(rr_prob)
    rr_continue = sampler.next_1d() < rr_prob
    active = active_next & (~rr_active | rr_continue) & (throughput_max != 0.0)
    return loop_state(locals())


LOOP_STATE: tuple[str, ...] = path_vertex.__code__.co_varnames[:path_vertex.__code__.co_argcount]
"""The path loop's state (``dr.while_loop`` labels), in the order :func:`path_vertex` takes and returns it."""


def loop_state(scope: Mapping[str, Any]) -> tuple[Any, ...]:
    """The loop state's values from a scope that holds every :data:`LOOP_STATE` name (``locals()``)."""
    return tuple(scope[name] for name in LOOP_STATE)
