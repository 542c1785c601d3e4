"""The sheen lobe of hybridgen's Principled BSDF: Blender 4.2's microfiber sheen (Zeltner, Burley & Chiang 2022,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines") as a linearly transformed cosine.

Directions are unit vectors in the local shading frame (z = the shading normal) with the view direction ``wi``
in the upper hemisphere. The lobe lives in the sheen frame: x = ``wi`` projected on the surface (any tangent
when ``wi`` is the normal), z = the normal. Its "BSDF x cosine" is R D(wo), with

    D(wo) = z a^2 / (pi ((a x + b z)^2 + a^2 y^2 + z^2)^2)     (x, y, z: wo in the sheen frame)

the cosine lobe transformed by the inverse matrix [[a, 0, b], [0, a, 0], [0, 0, 1]]. D integrates to exactly 1
over the upper hemisphere (the transform keeps z's sign), so R is the lobe's directional albedo; a, b and R
depend on the view cosine and Sheen Roughness (:func:`~.principled_tables.sheen_ltc`, tables fitted to Cycles'
measured lobe). Sampling draws D exactly (a cosine direction transformed), so the pdf is D. Dr.Jit values of the
active Mitsuba variant.
"""
from __future__ import annotations

from typing import Any

import drjit as dr
import mitsuba as mi


def sheen_frame(wi: Any) -> tuple[Any, Any]:
    """(cos, sin) of the azimuth of ``wi`` about the normal: the sheen frame's x axis is (cos, sin, 0)."""
    length2 = wi.x * wi.x + wi.y * wi.y
    tilted = length2 > 1e-14
    inv = dr.rsqrt(dr.maximum(length2, 1e-14))
    return dr.select(tilted, wi.x * inv, 1.0), dr.select(tilted, wi.y * inv, 0.0)


def sheen_lobe(a: Any, b: Any, frame: tuple[Any, Any], wo: Any) -> Any:
    """D(wo) (sr^-1 times the cosine; 0 below the surface) in the sheen ``frame`` (:func:`sheen_frame`)."""
    c, s = frame
    x, y = c * wo.x + s * wo.y, c * wo.y - s * wo.x
    length2 = dr.square(a * x + b * wo.z) + dr.square(a * y) + dr.square(wo.z)
    value = wo.z * dr.square(a / dr.maximum(length2, 1e-30)) * dr.inv_pi
    return dr.select(wo.z > 0.0, value, 0.0)


def sample_sheen(a: Any, b: Any, frame: tuple[Any, Any], u: Any) -> Any:
    """A direction drawn with density :func:`sheen_lobe` for ``u`` in [0, 1)^2 (a cosine-distributed direction
    (concentric disk) mapped through the transform)."""
    disk = mi.warp.square_to_uniform_disk_concentric(u)
    z = dr.safe_sqrt(1.0 - dr.squared_norm(disk))
    local = dr.normalize(mi.Vector3f((disk.x - z * b) / a, disk.y / a, z))
    c, s = frame
    return mi.Vector3f(c * local.x - s * local.y, s * local.x + c * local.y, local.z)
