"""hybridgen's Principled BSDF with a frame per layer: what :class:`~.principled_bsdf.PrincipledBSDF` evaluates and
samples when it holds a normal map (``normal_map``: any material with a Normal map; ``coat_normal_map``: a coated
one with a Coat Normal map), so that the base bends with the Normal input's map, the coat with the Coat Normal
input's (unlinked: the shading normal) and the sheen with their mix, as Blender 4.2 does (:mod:`.principled_frames`).

Directions ``wo`` are in Mitsuba's shading-frame coordinates (``si.sh_frame``), as the BSDF interface passes them;
each layer's lobes see them in its own local coordinates. Reflections count where ``wo`` lies on the viewer's side
of the geometric surface, the glass's refraction on the other (Cycles' test; :mod:`.principled_frames`); the pdf is
the whole mixture's. Sampling picks a lobe as the single-frame BSDF does and draws it in its layer's frame. Dr.Jit
values of the active variant.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import drjit as dr
import mitsuba as mi

from . import principled_layers as layers_mod
from . import principled_lobes as lobes
from . import principled_sampling as sampling
from .principled_frames import (LayerFrame, bump_shadowing, layer_frame, normal_map_frame, reflects,
                               sheen_frame)


@dataclass
class Layered:
    """One shading point: inputs, layer weights (None when not asked for), the frames and the view in each."""

    inp: Any
    lay: Any
    base: LayerFrame
    coat: LayerFrame
    sheen: LayerFrame | None
    si_wi: Any  # the view, shading-frame coordinates
    ng: Any  # the geometric normal, shading-frame coordinates
    wi: Any  # ... in the base's local coordinates
    wi_coat: Any
    wi_sheen: Any


def setup(bsdf: Any, si: Any, active: Any, weights: bool = True) -> Layered:
    """The frames of ``bsdf`` (a :class:`~.principled_bsdf.PrincipledBSDF`) at ``si`` and, with ``weights``, its
    layer weights for the view ``si.wi``."""
    ng = si.to_local(si.n)
    base_map = coat_map = None
    if bsdf.normal_map is not None:
        base_map = normal_map_frame(bsdf.normal_map.eval_3(si, active), si.wi, ng)
    if bsdf.coat_normal_map is not None:
        coat_map = normal_map_frame(bsdf.coat_normal_map.eval_3(si, active), si.wi, ng)
    base = layer_frame(base_map, si.wi, bsdf._frame(si, active, base_map))
    coat = layer_frame(coat_map, si.wi)
    sheen = sheen_frame(base, coat, mi.Float(bsdf.coat)) if bsdf.sheen > 0 else None
    inp = bsdf._inputs(si, active)
    wi, wi_coat = base.local(si.wi), coat.local(si.wi)
    wi_sheen = sheen.local(si.wi) if sheen is not None else wi
    lay = layers_mod.layers(inp, wi, base.flip, wi_coat=wi_coat, wi_sheen=wi_sheen) if weights else None
    return Layered(inp, lay, base, coat, sheen, si.wi, ng, wi, wi_coat, wi_sheen)


def eval_pdf(state: Layered, wo: Any, active: Any) -> tuple[Any, Any]:
    """(BSDF x |cos| as a Spectrum, pdf) for ``wo`` in shading-frame coordinates."""
    inp = state.inp
    reflected = reflects(state.ng, state.si_wi, wo)
    coat = (state.wi_coat, state.coat.local(wo), reflected) if inp.has_coat else None
    sheen = (state.wi_sheen, state.sheen.local(wo), reflected) if state.sheen is not None else None
    smooth = dr.select(state.si_wi.z < 0.0, -1.0, 1.0) * mi.Vector3f(0.0, 0.0, 1.0)
    diffuse_scale = (mi.Float(1.0) if state.base.frame is None else bump_shadowing(smooth, state.base.normal(), wo),
                     mi.Float(1.0) if state.sheen is None else bump_shadowing(smooth, state.sheen.normal(), wo))
    value, pdf = layers_mod.eval_pdf(state.lay, state.wi, state.base.local(wo), inp.has_coat,
                                     inp.has_transmission, inp.has_sheen, coat=coat, sheen_dirs=sheen,
                                     base_ok=reflected, diffuse_scale=diffuse_scale)
    ok = active & (state.wi.z > 0.0)
    return dr.select(ok, mi.Spectrum(value), 0.0), dr.select(ok, pdf, 0.0)


def sample(state: Layered, sample1: Any, sample2: Any, active: Any) -> tuple[Any, Any]:
    """(BSDFSample3f, weight) as :meth:`~.principled_bsdf.PrincipledBSDF.sample`: the lobe picked and drawn in its
    layer's frame with ``sample2`` (:func:`~.principled_sampling.split`; ``sample1``: the glass's choice)."""
    inp, lay, wi = state.inp, state.lay, state.wi
    choice, sample2 = sampling.split(lay, sample1, sample2, inp.has_sheen)
    alpha_x = dr.select(choice.pick_glass, lay.alpha_glass, lay.ax)
    alpha_y = dr.select(choice.pick_glass, lay.alpha_glass, lay.ay)
    wo, refract = sampling.draw(lay, wi, choice, sample2, alpha_x, alpha_y, inp.has_transmission)
    side = dr.select(refract, wo.z < 0.0, wo.z > 0.0)  # the drawn lobe's hemisphere in its own frame
    wo = state.base.shading(wo)
    if inp.has_coat:
        wi_c = state.wi_coat
        h_c = lobes.sample_visible_normal(wi_c, lay.alpha_coat, lay.alpha_coat, sample2)
        wo_c = 2.0 * dr.dot(h_c, wi_c) * h_c - wi_c
        wo = dr.select(choice.pick_coat, state.coat.shading(wo_c), wo)
        side = dr.select(choice.pick_coat, wo_c.z > 0.0, side)
    if inp.has_sheen:
        from . import principled_sheen as sheen

        assert state.sheen is not None
        wo_s = sheen.sample_sheen(lay.sheen_a, lay.sheen_b, lay.sheen_frame, sample2)
        wo = dr.select(choice.pick_sheen, state.sheen.shading(wo_s), wo)
        side = dr.select(choice.pick_sheen, wo_s.z > 0.0, side)
    value, pdf = eval_pdf(state, wo, active)
    ok = active & (wi.z > 0.0) & (pdf > 0.0) & side
    bs = sampling.sample_record(wo, pdf, ok, refract, choice, lay)
    return bs, dr.select(ok, value / dr.maximum(pdf, 1e-20), 0.0)


def emission_weight(bsdf: Any, si: Any, active: Any, layers: bool = True) -> Any:
    """What the sheen and coat of ``bsdf`` leave of its emission seen from ``si.wi``, in their own frames
    (``layers``: see :func:`~.principled_layers.emission_weight`)."""
    state = setup(bsdf, si, active, weights=False)
    return layers_mod.emission_weight(state.inp, state.wi_sheen, state.wi_coat, layers)
