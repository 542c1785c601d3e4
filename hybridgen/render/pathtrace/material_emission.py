"""What an emissive material emits: ``emission`` (or ``emission_texture``) x ``emission_strength``.

Blender's Principled BSDF emits Emission color x Emission Strength (radiance, W sr^-1 m^-2) on both sides;
an image linked to the Emission input replaces the color per texel (decoded from sRGB, sampled with the
mesh UVs, repeating, bilinear). The Mitsuba scene gives such a surface an ``area`` emitter whose radiance
is a linear bitmap of texture x strength; light selection weighs it by its mean radiance.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import InputError
from ...scene.material import Material
from ...scene.mesh_object import MeshObject
from ..material_textures import data_image
from ..tonemap import srgb_decode


def emission_image(material: Material, owner: str) -> np.ndarray | None:
    """HxWx3 float32 linear radiance of ``material``'s emission texture x strength (rows top-down as in the
    file); None without an emission texture."""
    texture = material.emission_texture
    if texture is None:
        return None
    if not isinstance(texture, str) and np.asarray(texture).ndim == 2:  # a gray array
        texture = np.repeat(np.asarray(texture)[..., None], 3, axis=-1)
    encoded = data_image(texture, owner, "emission_texture", channels=3).astype(np.float64)
    return (srgb_decode(encoded) * float(material.emission_strength)).astype(np.float32)


def emitted_radiance(obj: MeshObject) -> np.ndarray:
    """Mean linear RGB radiance (W sr^-1 m^-2) the object's surface emits: emission x emission_strength, or
    the emission texture's mean x strength (its mean over the image, not over the surface); a material with others
    mixed in emits their weighted sum (:mod:`.material_mixes`)."""
    material = obj.material
    if material.mixes:
        import copy

        from .material_mixes import mixed_radiance

        def radiance_of(part: Material) -> np.ndarray:
            twin = copy.copy(obj)
            twin.material = part
            return emitted_radiance(twin)

        return mixed_radiance(material, obj.name, radiance_of)
    strength = float(material.emission_strength)
    if material.emission_texture is not None and strength != 0:
        image = emission_image(material, obj.name)
        assert image is not None
        radiance = image.reshape(-1, 3).astype(np.float64).mean(axis=0)
    else:
        radiance = np.asarray(material.emission, float)[:3] * strength
    if np.any(radiance < 0) or not np.all(np.isfinite(radiance)):
        raise InputError(f"object '{obj.name}': emission must be finite and >= 0, got {radiance.tolist()}")
    return radiance


def radiance_texture(obj: MeshObject) -> dict[str, Any]:
    """The Mitsuba texture (constant ``rgb`` or linear ``bitmap``) of the radiance ``obj`` emits."""
    image = emission_image(obj.material, obj.name) if obj.material.emission_strength != 0 else None
    if image is None:
        return {"type": "rgb", "value": [float(v) for v in emitted_radiance(obj)]}
    import mitsuba as mi

    return {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(image)), "raw": True}
