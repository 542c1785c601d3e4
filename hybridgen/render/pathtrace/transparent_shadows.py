"""Transparent shadows of alpha (``mask``) surfaces, as Cycles casts them.

Cycles' shadow rays pass through transparent surfaces (an alpha-0 texel, a cut-out, a fractional BLEND
alpha), weighted by their transparency, up to ``transparent_max_bounces`` surfaces (BlenderProc's
``transparency_bounces``, default 8); camera and bounce rays that pass through one do not spend a bounce.
Mitsuba's ``path`` integrator tests shadow rays for any hit, so a cut-out casts a full shadow of delta
lights (sun, point, spot), and area lights behind one are found by BSDF sampling alone (noisy).

Where the scene holds such surfaces (:func:`scene_has_masks`), color is traced with:

- JIT variants: :mod:`hybridgen.render.pathtrace.clamped_path` with ``transparent_shadows``: next-event estimation
  multiplies the light by :func:`shadow_transmittance` (the product of ``1 - opacity`` of every surface
  between the point and the light, 0 at an opaque one or past ``max_transparent`` surfaces), and a path
  passing through a null (transparent) sample keeps the MIS state of its last real vertex and its bounce
  count, so the BSDF-sampled and light-sampled estimates of light seen through a hole still sum to one;
- ``scalar_rgb``: Mitsuba's ``volpath``, which traces shadow rays through null interfaces in the same way
  (surfaces only here: no media are created).
"""
from __future__ import annotations

from typing import Any

from ...scene.material import Material
from ...scene.scene import Scene

MAX_TRANSPARENT = 8
"""Transparent surfaces a shadow ray or path passes at most (Cycles' transparent_max_bounces as BlenderProc
sets it: ``transparency_bounces`` 8)."""


def has_mask(material: Material) -> bool:
    """True if the material's Mitsuba BSDF is wrapped in a ``mask`` (an alpha map, or alpha below 1 that
    ``alpha_mode`` keeps: any for BLEND, below 0.5 for CLIP) - see :func:`hybridgen.render.pathtrace.mitsuba_materials.bsdf_dict`."""
    if material.alpha_texture is not None:
        return True
    return material.alpha < (0.5 if material.alpha_mode == "CLIP" else 1.0)


def scene_has_masks(scene: Scene) -> bool:
    """True if any object of ``scene`` has a transparent (masked) surface."""
    return any(has_mask(obj.material) for obj in scene.objects)


def shadow_transmittance(scene: Any, si: Any, ds: Any, active: Any, max_surfaces: int = MAX_TRANSPARENT) -> Any:
    """Spectrum transmitted from the surface point ``si`` to the emitter sample ``ds``: the product of
    ``1 - opacity`` of the null (mask) surfaces in between, 0 if an opaque surface or more than
    ``max_surfaces`` transparent ones are in the way. Traced in the active JIT variant."""
    import drjit as dr
    import mitsuba as mi

    def step(ray: Any, transmittance: Any, count: Any, lane: Any) -> tuple[Any, Any, Any, Any]:
        hit = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=False, active=lane)
        blocked = lane & hit.is_valid()
        bsdf = hit.bsdf(ray)
        null = mi.has_flag(bsdf.flags(), mi.BSDFFlags.Null)
        passed = bsdf.eval_null_transmission(hit, blocked & null)
        count = dr.select(blocked, count + 1, count)
        through = blocked & null & (count <= max_surfaces)
        transmittance = dr.select(blocked, dr.select(through, transmittance * passed, 0.0), transmittance)
        lane = through & (dr.max(mi.unpolarized_spectrum(transmittance)) > 0)
        return hit.spawn_ray_to(ds.p), transmittance, count, lane

    state = (si.spawn_ray_to(ds.p), dr.select(active, mi.Spectrum(1.0), mi.Spectrum(0.0)), mi.UInt32(0),
             mi.Bool(active))
    state = dr.while_loop(state, lambda ray, transmittance, count, lane: lane,
                          lambda ray, transmittance, count, lane: step(ray, transmittance, count, lane),
                          label="hybridgen transparent shadow")
    return state[1]
