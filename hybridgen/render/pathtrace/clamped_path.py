"""A unidirectional path tracer with Cycles-style indirect clamping (firefly control), as a Mitsuba plugin.

Mitsuba's ``path`` integrator has no clamp. This one is the same estimator (next-event estimation of one
emitter per vertex, BSDF sampling, power-heuristic MIS between them, Russian roulette from ``rr_depth`` -
with Cycles' continuation probability ``min(sqrt(max throughput), 1)`` instead of Mitsuba's
``min(max throughput x eta^2, 0.95)``, which ended too many paths: window room of tools/color_quality.py,
160x120, glossy/transmission bounces 0, PSNR against a 2048-spp reference at 64 / 256 spp 30.8 / 36.5 dB
-> 31.8 / 37.7 dB for ~the same CPU time (no roulette at all: 32.6 / 38.4 dB for 15-20 % more; Cycles at
BlenderProc's defaults: 32.1 / 38.6 dB))
with one addition, ``clamp_indirect`` (linear radiance, W sr^-1 m^-2; 0 = off), which has the meaning of
Cycles' ``sample_clamp_indirect``: every *indirect* contribution of a sample - light that reached the
camera after at least one bounce, i.e. next-event estimation at the second or later path vertex and
emission found at the third or later - is scaled down so that the sum of its RGB components is at most three
times the clamp (Cycles' ``film_clamp_light``: its scene sync multiplies the clamp by 3 and the kernel compares
the sum of the absolute components, so grey light is clamped at the clamp per channel and saturated light is
left up to three times brighter in its channel). Direct light (emitters seen by the camera, and light
reflected once towards it) is never changed. Every contribution, direct or not, clamped or not, first has
its non-finite components set to 0, as Cycles' ``ensure_finite`` does there: a NaN or infinite sample would
otherwise make its pixel's error estimate NaN, which adaptive sampling reads as converged, and the denoiser
would spread it over its neighbours.
Clamping removes the rare, very bright samples (fireflies: caustics of glossy objects seen via a diffuse
surface) at the price of a small downward bias of bright indirect light; ``tools/bench_color.py`` measures
it against an unclamped reference.

``filter_glossy`` (Cycles' ``blur_glossy``; 0 = off): glossy lobes roughened after rough bounces, see
:mod:`hybridgen.render.pathtrace.glossy_filter` (the integrator tracks the path's smallest BSDF-sampling pdf and hands
each vertex its roughness floor).

``caustics_refractive`` (Cycles' option of that name; default true): false drops refraction at every vertex a
diffuse BSDF sample led to, as Cycles drops refraction closures on ``PATH_RAY_DIFFUSE`` rays - a light sample
across a surface with a glossy or sharp transmission lobe (:func:`refracts`) contributes nothing there, and a
sampled refraction ends the path. Glass seen by the camera or through mirrors is unchanged; light reaching diffuse
surfaces only through glass is not rendered (a bias, measured in docs/color_quality.md).

Per-lobe bounce limits as Cycles'' ``diffuse_bounces`` / ``glossy_bounces`` / ``transmission_bounces``
(``max_diffuse`` / ``max_glossy`` / ``max_transmission``; -1 = only ``max_depth`` limits): a path that
exceeds one still collects the emission its last BSDF sample finds (so MIS with next-event estimation
stays complete, as at ``max_depth``) and then ends. Glossy counts glossy and specular reflection;
transmission counts glossy and specular transmission; passing through a ``mask`` (alpha) counts as none.

Singular surfaces as Cycles': a principled metal or glass (no diffuse lobe) whose roughness (after the glossy
filter's floor) is at most :data:`SINGULAR_ROUGHNESS` gets no next-event estimation and its BSDF samples count
as delta for MIS (a hit emitter's full weight), as Cycles drops ``SD_BSDF_HAS_EVAL`` for microfacet closures with
``alpha_x alpha_y <= 2e-10`` (``BSDF_ROUGHNESS_SQ_THRESH``). Mitsuba's principled BSDF keeps a minimum alpha
instead, so a roughness-0 glass or mirror showed a point light's highlight Cycles does not render: a sub-pixel
spot of enormous radiance that even a 2048-spp reference does not resolve. Measured on the materials scene of
tools/color_quality.py (160x120, defaults, denoised, PSNR against a 2048-spp reference of the same
estimator): with BlenderProc's glossy/transmission bounces 0 the spot sat on the black glass and held 81 % of
the error (42.5 dB; 49.7 dB without its 6x6 px); now 50.5 dB. With 3 bounces per lobe 47.0 -> 48.3 dB.
The per-lane test (:func:`is_singular`: two attribute queries and three attribute evaluations, each a dispatch to
the BSDF) runs only in scenes with a material that can be singular (:func:`may_be_singular`, set after loading as
:attr:`singular_surfaces`); elsewhere no lane is singular and the kernel skips it - same values, and 4 % less time
for a default frame of the tabletop of tools/color_quality.py (320x240, 5 alternating pairs in one process:
render_color 3.70 -> 3.54 s wall, 7.27 -> 6.95 s CPU, the same bytes; the test cost ~80 of ~800 ns per sample on
the pixels that reach 1024 spp, the objects).

Shadow rays are traced only where the light sample can contribute: the emitter is sampled without Mitsuba's
visibility test, the BSDF evaluated, and the shadow ray (the segment Mitsuba's own test would trace) cast only on
lanes where both the BSDF value and the emitter's weight are non-zero - not from the side of an opaque surface
that faces away from the light, nor where the light sample missed. The values are the same bytes as with
Mitsuba's test (the tabletop and materials scenes of tools/color_quality.py, 160x120, 32 spp); default frames of
the tabletop take 5-10 % less time (320x240, 9 alternating pairs in one process: medians 3.72 -> 3.33 s and 3.85
-> 3.64 s wall in two runs), fixed 64-spp renders of the materials and HDRI tabletop scenes ~1 % less.

Depth is counted as Mitsuba's ``max_depth`` (path segments; ``max_depth = 2`` is direct light only). The
plugin is written in Python and traced once into the JIT kernel, so it costs what the built-in integrator
costs in the ``llvm``/``cuda`` variants; in ``scalar_rgb`` it would run Python per sample, so the color
view uses the built-in ``path`` integrator there (no clamping) and says so in the run's attributes.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

from .lobe_tests import SINGULAR_ROUGHNESS, is_singular, may_be_singular, refracts, transmission
from .path_vertex import LOOP_STATE, loop_state, path_vertex

__all__ = ["CYCLES_CLAMP_SCALE", "PLUGIN_NAME", "SINGULAR_ROUGHNESS", "is_singular", "may_be_singular", "refracts",
           "register", "transmission"]

PLUGIN_NAME = "hybridgen_clamped_path"
CYCLES_CLAMP_SCALE = 3.0
"""The clamp is compared with the sum of a contribution's RGB components after multiplying it by this (Cycles'
``Integrator::device_update``: ``sample_clamp_indirect * 3.0f``), so a grey contribution is clamped per channel
at ``clamp_indirect`` itself."""


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register the integrator plugin for ``variant`` (must be the active, JIT variant)."""
    import drjit as dr
    import mitsuba as mi

    class ClampedPath(mi.SamplingIntegrator):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.max_depth = int(props.get("max_depth", 5))
            self.rr_depth = int(props.get("rr_depth", 5))
            self.clamp_indirect = float(props.get("clamp_indirect", 0.0))
            self.limits = tuple(int(props.get(k, -1)) for k in ("max_diffuse", "max_glossy", "max_transmission"))
            # hybridgen/render/pathtrace/transparent_shadows.py: shadow rays through masks, null passes cost no bounce
            self.transparent_shadows = bool(props.get("transparent_shadows", False))
            self.filter_glossy = float(props.get("filter_glossy", 0.0))  # Cycles' blur_glossy (render/pathtrace/glossy_filter.py)
            # Cycles' caustics_refractive: False drops refraction at vertices reached by a diffuse bounce
            self.caustics_refractive = bool(props.get("caustics_refractive", True))
            # hybridgen/render/pathtrace/camera_hidden_emission.py: emitters the camera sees as their BSDF (set after load)
            self.hidden_shapes: list[Any] = []
            # hybridgen/render/pathtrace/layered_emission.py: emitters under a coat or sheen (set after load)
            self.layered_emitters: list[Any] = []
            # hybridgen/render/pathtrace/world_guide.py: light samples of an enclosed constant world (set per keypoint)
            self.world_guide: Any = None  # world_guide.JitGuide
            # whether any material of the scene may_be_singular (set after load): False skips the per-lane test
            self.singular_surfaces = True

        def _camera_hidden(self, si: Any) -> Any:
            """True where ``si`` lies on one of :attr:`hidden_shapes`."""
            hidden = mi.Bool(False)
            for shape in self.hidden_shapes:
                hidden |= si.shape == mi.ShapePtr(shape)
            return hidden

        @staticmethod
        def _mis_weight(pdf_a: Any, pdf_b: Any) -> Any:
            """Power heuristic."""
            a2, b2 = dr.square(pdf_a), dr.square(pdf_b)
            w = a2 / (a2 + b2)
            return dr.select(dr.isfinite(w), w, 0.0)

        def _clamped(self, contribution: Any, indirect: Any) -> Any:
            """``contribution`` (linear RGB) with non-finite components set to 0 and, where ``indirect``, scaled
            to at most ``3 x clamp_indirect`` in the sum of its components (Cycles' ``film_clamp_light``)."""
            contribution = dr.select(dr.isfinite(contribution), contribution, 0.0)
            if self.clamp_indirect <= 0:
                return contribution
            limit = CYCLES_CLAMP_SCALE * self.clamp_indirect
            total = dr.sum(dr.abs(contribution))
            return contribution * dr.select(indirect & (total > limit), limit / total, 1.0)

        def sample(self, scene: Any, sampler: Any, ray: Any, medium: Any = None, active: Any = True) -> Any:
            """Radiance of one path per lane. The bounce loop is an explicit ``dr.while_loop`` (traced once into
            the kernel); branches on Python values (``filter_glossy > 0``, ``guide is not None`` ...) are plain
            ifs decided while tracing - there is no branch on a Dr.Jit value, all per-lane choices are masks."""
            mis_weight = self._mis_weight
            transparent = self.transparent_shadows
            hidden = mi.Bool(False)
            n_transparent = mi.UInt32(0)
            bsdf_ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray)
            depth = mi.UInt32(0)
            radiance = mi.Spectrum(0.0)
            throughput = mi.Spectrum(1.0)
            eta = mi.Float(1.0)
            active = mi.Bool(active)
            si_prev = dr.zeros(mi.SurfaceInteraction3f)
            bsdf_pdf_prev = mi.Float(1.0)
            bsdf_delta_prev = mi.Bool(True)
            diffuse_prev = mi.Bool(False)  # this vertex was reached by a diffuse BSDF sample (Cycles' PATH_RAY_DIFFUSE)
            max_depth, rr_depth = mi.UInt32(self.max_depth), mi.UInt32(self.rr_depth)
            big = 2 ** 30
            max_diffuse, max_glossy, max_transmission = (mi.UInt32(big if v < 0 else v) for v in self.limits)
            n_diffuse, n_glossy, n_transmission = mi.UInt32(0), mi.UInt32(0), mi.UInt32(0)
            last_segment = mi.Bool(False)  # a lobe limit was exceeded: collect emission, then stop
            filter_glossy = self.filter_glossy
            min_ray_pdf = mi.Float(dr.inf)  # smallest BSDF-sampling pdf of the path so far (filter glossy)
            guide = self.world_guide if not transparent else None
            world_radiance = guide.radiance if guide is not None else None
            guided_prev = mi.Bool(False)  # the previous vertex took a guided world sample (MIS for world hits)

            state = dr.while_loop(loop_state(locals()), lambda active, *rest: active, path_vertex,
                                  labels=LOOP_STATE, max_iterations=-1, label="hybridgen clamped path")
            return state[LOOP_STATE.index("radiance")], mi.Bool(True), []

        def aov_names(self) -> list[str]:
            return []

        def to_string(self) -> str:
            return (f"HybridgenClampedPath[max_depth={self.max_depth}, clamp_indirect={self.clamp_indirect}, "
                    f"lobe limits (diffuse, glossy, transmission)={self.limits}]")

    mi.register_integrator(PLUGIN_NAME, lambda props: ClampedPath(props))
