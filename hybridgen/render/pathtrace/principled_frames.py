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
A normal map's frame is Mitsuba's ``normalmap`` plugin's exactly (its ``flip_invalid_normals``: a perturbed
normal facing away from the viewer has its tangent components mirrored; tangent s = x minus its normal part),
so the base of a coated material bends as an uncoated one does under the ``normalmap`` wrapper. Dr.Jit values of
the active variant.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import drjit as dr
import mitsuba as mi


def normal_map_frame(value: Any, wi: Any) -> Any:
    """The frame (in shading-frame coordinates) of a tangent-space normal map's texel ``value`` (RGB 0..1, x along
    the shading frame's s, y along t) for the view direction ``wi`` (shading-frame coordinates)."""
    n = mi.Vector3f(2.0 * value[0] - 1.0, 2.0 * value[1] - 1.0, 2.0 * value[2] - 1.0)
    invalid = wi.z * dr.dot(wi, n) <= 0.0
    n = dr.normalize(mi.Vector3f(dr.select(invalid, -n.x, n.x), dr.select(invalid, -n.y, n.y), n.z))
    s = dr.normalize(mi.Vector3f(1.0, 0.0, 0.0) - n * n.x)
    return mi.Frame3f(s, dr.cross(n, s), n)


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

    def same_side(self, wo: Any) -> Any:
        """Mitsuba's ``normalmap`` test: ``wo`` (shading-frame coordinates) lies on the same side of this frame's
        normal as of the shading normal (always true for the shading frame itself)."""
        if self.frame is None:
            return mi.Bool(True)
        return wo.z * self.frame.to_local(wo).z > 0.0

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


def reflects_in(frame: LayerFrame, wi: Any, wo: Any) -> Any:
    """Whether ``wo`` is a reflection (same side as ``wi``) about ``frame``'s normal exactly when it is one about the
    shading normal (shading-frame coordinates): the test for the sheen's mixed normal, which has no map of its own."""
    return (wo.z * wi.z > 0.0) == (frame.local(wo).z > 0.0)
