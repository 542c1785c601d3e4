"""Blender's default anisotropy tangent for hybridgen's Principled BSDF: radial about the object's local Z axis.

An unlinked Tangent input of Blender 4.2's Principled BSDF is Cycles' Tangent node in "radial, Z" mode on the
mesh's generated coordinates g (the object-space position mapped into the mesh's bounding box, the automatic
texture space: g = (p - centre) / (2 half_size) + 1/2 per axis, a zero extent counting as half size 1):
T_object = (-(g_y - 1/2), g_x - 1/2, 0), turned into world axes with the object's matrix (scale included), then
made perpendicular to the shading normal. With or without UVs: Cycles never takes the UV tangent unless a Tangent
node in UV mode is linked.

hybridgen hands T_world per vertex to Mitsuba as the mesh attribute :data:`ATTRIBUTE` (of the meshes whose
material is anisotropic, :func:`needs_radial_tangent`); T_object is affine in the position, so Mitsuba's
barycentric interpolation gives Cycles' value at every point. The BSDF projects it onto the shading plane
(:mod:`.principled_bsdf`). Such meshes are not instanced (an attribute does not follow an instance's
transform).
"""
from __future__ import annotations

import numpy as np

from ...scene.material import Material

ATTRIBUTE = "vertex_hg_radial_tangent"
"""The mesh attribute (3 floats per vertex, world axes, unnormalized) holding the radial tangent."""


def needs_radial_tangent(material: Material) -> bool:
    """Whether the material's Principled BSDF is anisotropic (Blender's ``Anisotropic`` > 0)."""
    try:
        return float(material.extra.get("anisotropic", 0.0)) > 0.0
    except (TypeError, ValueError):
        return False  # the material check names the bad value


def radial_tangents(vertices: np.ndarray, local2world: np.ndarray) -> np.ndarray:
    """Blender's radial-Z tangent (world axes, unnormalized, float32 V x 3) at the object-space ``vertices``
    (V x 3, m) of a mesh placed by ``local2world`` (4 x 4)."""
    vertices = np.asarray(vertices, np.float64)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    centre, half = (low + high) / 2.0, (high - low) / 2.0
    half = np.where(half == 0.0, 1.0, np.maximum(half, 1e-5))  # Blender's texture-space floor
    generated = (vertices - centre) / (2.0 * half)  # g - 1/2
    tangent = np.stack([-generated[:, 1], generated[:, 0], np.zeros(len(vertices))], axis=1)
    return (tangent @ np.asarray(local2world, np.float64)[:3, :3].T).astype(np.float32)
