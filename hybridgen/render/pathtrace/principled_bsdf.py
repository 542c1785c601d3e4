"""hybridgen's Principled BSDF: Blender 4.2's Principled BSDF (what BlenderProc 2.8 renders with) as a Mitsuba 3
plugin, :data:`PLUGIN_NAME`.

Inputs carry Blender's names (docs/principled_bsdf.md lists them with their ranges): ``base_color`` (texture),
``roughness``, ``metallic``, ``specular`` (Specular IOR Level; each a value or a texture), ``specular_tint``
(RGB), ``ior``, ``transmission``, ``anisotropic``, ``anisotropic_rotation`` (turns of the tangent around the
normal; the tangent is Blender's default, radial about the object's Z axis, :mod:`.principled_tangent`),
``coat_weight``, ``coat_roughness``, ``coat_ior``, ``coat_tint`` (RGB), ``sheen_weight``, ``sheen_roughness``,
``sheen_tint`` (RGB), ``subsurface_weight`` (its diffuse fallback).
Roughness maps to GGX alpha = roughness^2 as in Blender. The layering is :mod:`.principled_layers`', the lobes
:mod:`.principled_lobes`'. The BSDF is two-sided as Blender's: a hit from the back is shaded as from the
front with the normal flipped, except that transmission then leaves the solid (relative IOR 1/IOR). Emission
stays the scene's area emitter and alpha the ``mask`` wrapper (:mod:`.mitsuba_materials`).

Sampling picks one lobe with probability proportional to its estimated albedo (Cycles' sample weights, plus
:data:`~.principled_layers.MIN_LOBE_SHARE`), draws a direction from it (visible GGX normals, a cosine
lobe for the diffuse base, the transformed cosine for sheen) and returns the whole BSDF's value over the whole
mixture's pdf, so ``sample``, ``eval``, ``pdf`` and ``eval_pdf`` agree exactly at every sampled direction.
``refraction_pairs`` (:data:`REFRACTION_PAIRS`): ``cycles`` (the default) also values the refraction pairs no
microfacet connects, as Cycles 4.2 does (light samples reach them, BSDF samples never), ``physical`` values only
real refractions, so that ``eval`` and ``pdf`` integrate to what sampling returns. The BSDF answers
``has_attribute`` / ``eval_attribute_1`` for ``roughness``, ``metallic`` and ``spec_trans`` (the transmission weight) as Mitsuba's ``principled`` does,
which the path tracer's singular-surface test reads.

Registered per JIT variant by :func:`register`. In ``scalar_rgb`` hybridgen keeps Mitsuba's ``principled``
(a Python BSDF there would be called once per ray from C++; see :func:`available`).
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

from .mitsuba_variant import is_jit

PLUGIN_NAME = "hybridgen_principled"
REFRACTION_PAIRS = ("cycles", "physical")
"""Values of the plugin's ``refraction_pairs``: which direction pairs the rough refraction lobe values
(:func:`~.principled_lobes.refraction`: ``cycles`` = every pair across the surface, Blender 4.2's evaluation;
``physical`` = the pairs some microfacet refracts into each other)."""
DEFAULT_REFRACTION_PAIRS = "cycles"


def available(variant: str) -> bool:
    """Whether hybridgen renders its Principled BSDF in ``variant`` (the JIT variants), registering it there."""
    if not variant or not is_jit(variant):
        return False
    register(variant)
    return True


def _flags() -> Any:
    import mitsuba as mi

    return mi.BSDFFlags


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register :data:`PLUGIN_NAME` for ``variant`` (the active variant)."""
    import drjit as dr
    import mitsuba as mi

    from . import principled_layers as layers_mod

    flags = _flags()
    both = flags.FrontSide | flags.BackSide

    def value_or_texture(props: Any, name: str, default: float) -> Any:
        value = props.get(name, default)
        return value if isinstance(value, mi.Texture) else float(value)

    def read(value: Any, si: Any, active: Any) -> Any:
        return value.eval_1(si, active) if isinstance(value, mi.Texture) else mi.Float(value)

    def color(props: Any, name: str) -> Any:
        value = props.get(name, 1.0)
        return mi.ScalarColor3f(value) if not isinstance(value, (int, float)) else mi.ScalarColor3f(float(value))

    def texture(props: Any, name: str) -> Any:
        """The texture ``name`` (a constant RGB given as a color made one), or None."""
        value = props.get(name, None)
        if value is None or isinstance(value, mi.Texture):
            return value
        return mi.load_dict({"type": "rgb", "value": list(mi.ScalarColor3f(value))})

    class PrincipledBSDF(mi.BSDF):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.base_color = props.get("base_color")
            if not isinstance(self.base_color, mi.Texture):
                self.base_color = mi.load_dict({"type": "rgb", "value": list(color(props, "base_color"))})
            self.roughness = value_or_texture(props, "roughness", 0.5)
            self.metallic = value_or_texture(props, "metallic", 0.0)
            self.specular = value_or_texture(props, "specular", 0.5)
            self.ior = float(props.get("ior", 1.5))
            self.spec_tint = color(props, "specular_tint")
            self.transmission = float(props.get("transmission", 0.0))
            self.aspect = (1.0 - 0.9 * min(max(float(props.get("anisotropic", 0.0)), 0.0), 1.0)) ** 0.5
            self.rotation = float(props.get("anisotropic_rotation", 0.0))
            self.coat = max(float(props.get("coat_weight", 0.0)), 0.0)
            self.coat_rough = min(max(float(props.get("coat_roughness", 0.03)), 0.0), 1.0)
            self.coat_ior = max(float(props.get("coat_ior", 1.5)), 1.0)
            self.coat_tint = color(props, "coat_tint")
            self.sheen = max(float(props.get("sheen_weight", 0.0)), 0.0)
            self.sheen_rough = min(max(float(props.get("sheen_roughness", 0.5)), 0.0), 1.0)
            self.sheen_tint = color(props, "sheen_tint")
            self.subsurface = min(max(float(props.get("subsurface_weight", 0.0)), 0.0), 1.0)
            self.refraction_pairs = str(props.get("refraction_pairs", DEFAULT_REFRACTION_PAIRS))
            if self.refraction_pairs not in REFRACTION_PAIRS:
                raise ValueError(f"refraction_pairs must be one of {REFRACTION_PAIRS}, got '{self.refraction_pairs}'")
            # tangent-space normal maps of the Normal and Coat Normal inputs (principled_frames.py, Cycles' rules):
            # a coat bends only with its own map
            self.normal_map, self.coat_normal_map = (texture(props, name) for name in ("normal_map", "coat_normal_map"))
            self.layer_frames = self.normal_map is not None or self.coat_normal_map is not None
            components = [flags.DiffuseReflection | both, flags.GlossyReflection | both]
            if self.transmission > 0:
                components.append(flags.GlossyTransmission | flags.NonSymmetric | both)
            self.m_components = components  # (the property returns a copy: assign the whole list)
            self.m_flags = flags.Empty
            for component in components:
                self.m_flags = self.m_flags | component

        def _inputs(self, si: Any, active: Any) -> Any:
            return layers_mod.Inputs(
                base=self.base_color.eval(si, active), rough=dr.clip(read(self.roughness, si, active), 0.0, 1.0),
                metallic=dr.clip(read(self.metallic, si, active), 0.0, 1.0),
                level=dr.maximum(read(self.specular, si, active), 0.0), ior=mi.Float(max(self.ior, 1e-5)),
                spec_tint=mi.Color3f(self.spec_tint), transmission=mi.Float(min(max(self.transmission, 0.0), 1.0)),
                aspect=mi.Float(self.aspect), coat=mi.Float(self.coat), coat_rough=mi.Float(self.coat_rough),
                coat_ior=mi.Float(self.coat_ior), coat_tint=mi.Color3f(self.coat_tint), has_coat=self.coat > 0,
                has_transmission=self.transmission > 0, has_coat_tint=any(c != 1.0 for c in self.coat_tint),
                sheen=mi.Float(self.sheen), sheen_rough=mi.Float(self.sheen_rough),
                sheen_tint=mi.Color3f(self.sheen_tint), subsurface=mi.Float(self.subsurface),
                has_sheen=self.sheen > 0, has_subsurface=self.subsurface > 0,
                every_refraction_pair=self.refraction_pairs == "cycles")

        def _frame(self, si: Any, active: Any, base: Any = None) -> Any:
            """Rotation of local directions into the anisotropy frame: Blender's default tangent (radial about
            the object's Z axis, the mesh attribute :data:`~.principled_tangent.ATTRIBUTE`; Mitsuba's shading
            tangent where a mesh has none) turned by the rotation; ``base``: the base layer's frame in
            shading-frame coordinates (a normal map's; None: the shading frame)."""
            angle = 2.0 * dr.pi * self.rotation
            c, s = mi.Float(dr.cos(angle)), mi.Float(dr.sin(angle))
            if self.aspect >= 1.0:
                return c, s
            from .principled_tangent import ATTRIBUTE

            radial = si.shape.eval_attribute_3(ATTRIBUTE, si, active)
            tangent = si.sh_frame.to_local(mi.Vector3f(radial[0], radial[1], radial[2]))
            if base is not None:
                tangent = base.to_local(tangent)
            length2 = tangent.x * tangent.x + tangent.y * tangent.y
            found = length2 > 1e-20
            inv = dr.rsqrt(dr.maximum(length2, 1e-20))
            tc, ts = dr.select(found, tangent.x * inv, 1.0), dr.select(found, tangent.y * inv, 0.0)
            return tc * c - ts * s, ts * c + tc * s

        def _local(self, v: Any, flip: Any, rot: Any) -> Any:
            c, s = rot
            return mi.Vector3f(c * v.x + s * v.y, -s * v.x + c * v.y, dr.select(flip, -v.z, v.z))

        def _world_local(self, v: Any, flip: Any, rot: Any) -> Any:
            c, s = rot
            return mi.Vector3f(c * v.x - s * v.y, s * v.x + c * v.y, dr.select(flip, -v.z, v.z))

        def _setup(self, si: Any, active: Any) -> tuple[Any, Any, Any, Any, Any]:
            flip = mi.Frame3f.cos_theta(si.wi) < 0.0
            rot = self._frame(si, active)
            wi = self._local(si.wi, flip, rot)
            inp = self._inputs(si, active)
            return inp, layers_mod.layers(inp, wi, flip), wi, flip, rot

        def _layered(self, si: Any, active: Any) -> Any:
            """The inputs, per-layer frames and layer weights where the coat's normal differs from the base's."""
            from .principled_layered import setup

            return setup(self, si, active)

        def eval_pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> tuple[Any, Any]:
            if self.layer_frames:
                from .principled_layered import eval_pdf

                return eval_pdf(self._layered(si, active), wo, active)
            inp, lay, wi, flip, rot = self._setup(si, active)
            value, pdf = layers_mod.eval_pdf(lay, wi, self._local(wo, flip, rot), inp.has_coat,
                                             inp.has_transmission, inp.has_sheen)
            ok = active & (wi.z > 0.0)
            return dr.select(ok, mi.Spectrum(value), 0.0), dr.select(ok, pdf, 0.0)

        def eval(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self.eval_pdf(ctx, si, wo, active)[0]

        def pdf(self, ctx: Any, si: Any, wo: Any, active: Any = True) -> Any:
            return self.eval_pdf(ctx, si, wo, active)[1]

        def sample(self, ctx: Any, si: Any, sample1: Any, sample2: Any, active: Any = True) -> tuple[Any, Any]:
            from . import principled_sampling as sampling

            if self.layer_frames:
                from .principled_layered import sample

                return sample(self._layered(si, active), sample1, sample2, active)
            inp, lay, wi, flip, rot = self._setup(si, active)
            choice, sample2 = sampling.split(lay, sample1, sample2, inp.has_sheen)
            alpha_x = dr.select(choice.pick_coat, lay.alpha_coat, dr.select(choice.pick_glass, lay.alpha_glass, lay.ax))
            alpha_y = dr.select(choice.pick_coat, lay.alpha_coat, dr.select(choice.pick_glass, lay.alpha_glass, lay.ay))
            wo, refract = sampling.draw(lay, wi, choice, sample2, alpha_x, alpha_y, inp.has_transmission)
            if inp.has_sheen:
                from . import principled_sheen as sheen

                wo = dr.select(choice.pick_sheen,
                               sheen.sample_sheen(lay.sheen_a, lay.sheen_b, lay.sheen_frame, sample2), wo)
            value, pdf = layers_mod.eval_pdf(lay, wi, wo, inp.has_coat, inp.has_transmission, inp.has_sheen)
            ok = active & (wi.z > 0.0) & (pdf > 0.0) & dr.select(refract, wo.z < 0.0, wo.z > 0.0)
            bs = sampling.sample_record(self._world_local(wo, flip, rot), pdf, ok, refract, choice, lay)
            weight = mi.Spectrum(value) / dr.maximum(pdf, 1e-20)
            return bs, dr.select(ok, weight, 0.0)

        def emission_weight(self, si: Any, active: Any = True, layers: bool = True) -> Any:
            """What the sheen and coat leave of this material's emission seen from ``si.wi`` (a color; Cycles
            layers the emission under them; ``layers`` False: the coat tint's absorption alone,
            :func:`~.principled_layers.emission_weight`)."""
            if self.layer_frames:
                from .principled_layered import emission_weight

                return emission_weight(self, si, active, layers)
            wi = mi.Vector3f(si.wi.x, si.wi.y, dr.abs(si.wi.z))
            return layers_mod.emission_weight(self._inputs(si, active), wi, wi, layers)

        def eval_diffuse_reflectance(self, si: Any, active: Any = True) -> Any:
            return self.base_color.eval(si, active)

        def has_attribute(self, name: str, active: Any = True) -> Any:
            return mi.Bool(name in ("roughness", "metallic", "spec_trans", "base_color"))

        def eval_attribute_1(self, name: str, si: Any, active: Any = True) -> Any:
            if name == "roughness":
                return read(self.roughness, si, active)
            if name == "metallic":
                return read(self.metallic, si, active)
            if name == "spec_trans":
                return mi.Float(self.transmission)
            return mi.Float(0.0)

        def eval_attribute_3(self, name: str, si: Any, active: Any = True) -> Any:
            return self.base_color.eval(si, active) if name == "base_color" else mi.Color3f(0.0)

        def traverse(self, callback: Any) -> None:  # mi.traverse: "<bsdf>.<input>.<texture parameter>"
            for name in ("base_color", "roughness", "metallic", "specular"):
                if isinstance(getattr(self, name), mi.Texture):
                    callback.put(name, getattr(self, name), mi.ParamFlags.Differentiable)

        def parameters_changed(self, keys: Any = None) -> None:
            pass

        def to_string(self) -> str:
            return (f"HybridgenPrincipled[ior={self.ior}, transmission={self.transmission}, coat={self.coat}, "
                    f"sheen={self.sheen}, subsurface={self.subsurface}, roughness={self.roughness}, "
                    f"metallic={self.metallic}, specular={self.specular}]")

    mi.register_bsdf(PLUGIN_NAME, lambda props: PrincipledBSDF(props))
