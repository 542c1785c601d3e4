"""The shading frames of the layers of hybridgen's Principled BSDF when the coat's normal differs from the base's.

Blender 4.2's Principled BSDF bends each layer by its own normal (Cycles' ``svm_node_closure_bsdf``):

- the base (metal, transmission, specular, diffuse) by the Normal input N: a normal map linked to it, else the
  shading normal;
- the coat by the Coat Normal input: a normal map linked to it, else - unlinked - the shading normal *without*
  the base's normal map (Cycles' default link of a normal socket, the Geometry node's Normal; measured with bpy
  4.2, docs/principled_bsdf.md);
- the sheen by normalize(mix(N, coat normal, saturate(Coat Weight))).

So a material with a coat and a normal map (on either input) needs a frame per layer. :class:`LayerFrame` holds
one, as a rotation of Mitsuba's shading frame (``si.sh_frame``, the interpolated normal) followed by the mirror
hybridgen's BSDF applies to back-side views and, for the base, the anisotropy tangent's rotation: directions
go from shading-frame coordinates to a layer's local coordinates (z its normal on the viewer's side) and back.

A normal map's normal is Cycles' Normal Map node's (tangent space: x along the shading frame's s - dP/du made
perpendicular to the normal -, y along t = n x s, the OpenGL convention), then turned towards the geometric
normal just enough that the view's mirror direction stays above the surface (Cycles'
``ensure_valid_specular_reflection``, which both the node and the closures apply), and a layer's lobes count a
direction as reflected where it lies on the viewer's side of the geometric surface (Cycles' test) - not
Mitsuba's ``normalmap`` rules (a facing-away normal's tangent part mirrored; no value where the direction's side
differs between the mapped and the interpolated normal), which darken a strongly bumped sphere's rim:
docs/principled_bsdf.md has the measured difference. Dr.Jit values of the active variant.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import drjit as dr
import mitsuba as mi


def valid_reflection(ng: Any, wi: Any, n: Any) -> Any:
    """Cycles' ``ensure_valid_specular_reflection``: the unit normal ``n`` turned towards the geometric normal
    ``ng`` (both, and the view ``wi``, on the viewer's side) just enough that the mirror direction of ``wi`` rises
    min(0.9 wi.ng, 0.01) above the surface; ``n`` itself where it already does."""
    r = 2.0 * dr.dot(n, wi) * n - wi
    iz = dr.maximum(dr.dot(wi, ng), 0.0)
    threshold = dr.minimum(0.9 * iz, 0.01)
    x = n - dr.dot(n, ng) * ng  # the frame: z = ng, n in the x-z plane
    length = dr.norm(x)
    x = dr.select(length > 1e-12, x / dr.maximum(length, 1e-12), n)
    ix = dr.dot(wi, x)
    a = ix * ix + iz * iz
    b = 2.0 * (a + iz * threshold)
    c = dr.square(threshold + iz)
    root = dr.safe_sqrt(b * b - 4.0 * a * c)
    nz2 = dr.select(ix < 0.0, 0.25 * (b + root) / a, 0.25 * (b - root) / a)
    lifted = dr.safe_sqrt(1.0 - nz2) * x + dr.safe_sqrt(nz2) * ng
    return dr.select(dr.dot(ng, r) >= threshold, n, lifted)


def normal_map_frame(value: Any, wi: Any, ng: Any) -> Any:
    """The frame (in shading-frame coordinates) of a tangent-space normal map's texel ``value`` (RGB 0..1) for the
    view ``wi`` and the geometric normal ``ng`` (shading-frame coordinates): its normal made valid
    (:func:`valid_reflection`) on the viewer's side of the surface, its tangent s the shading frame's x made
    perpendicular to it."""
    n = dr.normalize(mi.Vector3f(2.0 * value[0] - 1.0, 2.0 * value[1] - 1.0, 2.0 * value[2] - 1.0))
    facing = dr.select(dr.dot(wi, ng) < 0.0, -1.0, 1.0)  # the viewer's side (back-side hits shade mirrored)
    n = dr.normalize(facing * valid_reflection(facing * ng, wi, facing * n))
    s = dr.normalize(mi.Vector3f(1.0, 0.0, 0.0) - n * n.x)
    return mi.Frame3f(s, dr.cross(n, s), n)


def reflects(ng: Any, wi: Any, wo: Any) -> Any:
    """Whether ``wo`` lies on the viewer's side of the geometric surface (normal ``ng``; shading-frame coordinates):
    where Cycles evaluates a reflection (and, where not, a refraction)."""
    return dr.dot(wo, ng) * dr.dot(wi, ng) > 0.0


def bump_shadowing(smooth: Any, n: Any, wo: Any) -> Any:
    """Cycles' softening of a diffuse closure bent away from the shading normal (Chiang, Li & Burley 2019,
    "Taming the Shadow Terminator"): g = (smooth.wo) / ((n.wo) (smooth.n)), 1 for g >= 1, 0 for g < 0, else
    g + g^2 - g^3 (``smooth``: the interpolated normal, ``n``: the closure's, both on the viewer's side)."""
    g = dr.dot(smooth, wo) / (dr.dot(n, wo) * dr.dot(smooth, n))
    g = dr.select(dr.isfinite(g), g, 0.0)
    return dr.select(g >= 1.0, 1.0, dr.select(g < 0.0, 0.0, g + g * g - g * g * g))


@dataclass
class LayerFrame:
    """A layer's frame: ``frame`` (shading-frame coordinates; None: the shading frame itself), ``flip`` (the view
    is below its normal: local z mirrored) and ``rot`` ((cos, sin) of the turn about the normal; (1, 0) none)."""

    frame: Any
    flip: Any
    rot: tuple[Any, Any]

    def local(self, v: Any) -> Any:
        """Shading-frame coordinates -> the layer's local coordinates."""
        if self.frame is not None:
            v = self.frame.to_local(v)
        c, s = self.rot
        return mi.Vector3f(c * v.x + s * v.y, -s * v.x + c * v.y, dr.select(self.flip, -v.z, v.z))

    def shading(self, v: Any) -> Any:
        """The layer's local coordinates -> shading-frame coordinates."""
        c, s = self.rot
        v = mi.Vector3f(c * v.x - s * v.y, s * v.x + c * v.y, dr.select(self.flip, -v.z, v.z))
        return v if self.frame is None else self.frame.to_world(v)

    def normal(self) -> Any:
        """The layer's normal on the viewer's side, in shading-frame coordinates."""
        n = mi.Vector3f(0.0, 0.0, 1.0) if self.frame is None else self.frame.n
        return dr.select(self.flip, -n, n)


def layer_frame(frame: Any, wi: Any, rot: tuple[Any, Any] | None = None) -> LayerFrame:
    """The :class:`LayerFrame` of ``frame`` (None: the shading frame) for the view ``wi`` (shading-frame
    coordinates): mirrored where ``wi`` lies below its normal, as the BSDF shades back sides."""
    cos_i = wi.z if frame is None else frame.to_local(wi).z
    return LayerFrame(frame, cos_i < 0.0, rot if rot is not None else (mi.Float(1.0), mi.Float(0.0)))


def sheen_frame(base: LayerFrame, coat: LayerFrame, coat_weight: Any) -> LayerFrame:
    """The sheen layer's frame: normal normalize(mix(base normal, coat normal, saturate(coat_weight))), both on
    the viewer's side (so never mirrored), any tangent (the sheen lobe is isotropic)."""
    n = dr.normalize(dr.lerp(base.normal(), coat.normal(), dr.clip(coat_weight, 0.0, 1.0)))
    return LayerFrame(mi.Frame3f(n), mi.Bool(False), (mi.Float(1.0), mi.Float(0.0)))
