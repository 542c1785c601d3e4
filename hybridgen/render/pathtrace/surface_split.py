"""Cycles' rule for its denoising features at one surface, for :mod:`hybridgen.render.pathtrace.specular_guides`:
whether a principled surface writes the albedo and normal guides where it is hit, or passes the feature path on
through its specular-like mirror and refraction directions, with what weight (float64 NumPy, one lane per ray)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...scene.material import Material

SPECULAR_ALPHA = 0.075
"""GGX alpha (roughness squared) at or below which Cycles counts a closure as specular-like for its denoising
features (``bsdf_get_specular_roughness_squared(sc) > sqr(0.075f)`` is diffuse-like)."""
NONSPECULAR_SHARE = 0.25
"""A surface writes the features when more than this share of its closures' sample weight is not specular-like
(Cycles: ``sum_nonspecular_weight * 4 > sum_weight``)."""


@dataclass(frozen=True)
class SurfaceLobes:
    """The lobe parameters of a principled material (one value per traced lane, float64 arrays)."""

    metallic: np.ndarray
    transmission: np.ndarray
    specular_f0: np.ndarray
    ior: np.ndarray
    specular_like: np.ndarray  # bool: the specular lobes are sharp enough to be looked through

    @staticmethod
    def of(materials: list[Material]) -> "SurfaceLobes":
        def values(name: str) -> np.ndarray:
            return np.array([float(getattr(m, name)) for m in materials], dtype=np.float64).reshape(-1)

        return SurfaceLobes(values("metallic"), values("transmission"), np.clip(0.08 * values("specular"), 0, 0.999),
                            values("ior"), np.array([can_be_specular_like(m) for m in materials], dtype=bool))


def can_be_specular_like(material: Material) -> bool:
    """Whether ``material``'s specular lobes are specular-like (roughness^2 <= :data:`SPECULAR_ALPHA`, no
    roughness/metallic map) and it has any (specular layer, metal or glass); never for a mix of materials (the
    denoising guides stay on its surface)."""
    if material.mixes:
        return False
    if material.roughness_texture is not None or material.metallic_texture is not None:
        return False
    has_specular = material.metallic > 0 or material.transmission > 0 or material.specular > 0
    return has_specular and float(material.roughness) ** 2 <= SPECULAR_ALPHA


def dielectric_fresnel(cos_i: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unpolarised Fresnel reflectance and the cosine of the refracted ray, for incidence cosines ``cos_i``
    (> 0, on the incident side) and relative IOR ``eta`` = n_transmitted / n_incident; total internal
    reflection gives F = 1 (and cos_t 0)."""
    cos_i = np.clip(cos_i, 0.0, 1.0)
    sin_t2 = (1.0 - cos_i ** 2) / eta ** 2
    cos_t = np.sqrt(np.clip(1.0 - sin_t2, 0.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
        r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    f = np.where(sin_t2 >= 1.0, 1.0, 0.5 * (r_s ** 2 + r_p ** 2))
    return np.nan_to_num(f, nan=1.0), np.where(sin_t2 >= 1.0, 0.0, cos_t)


def schlick(f0: np.ndarray, cos_i: np.ndarray) -> np.ndarray:
    """Schlick's Fresnel (N x 3) of a metal with normal-incidence reflectance ``f0`` (N x 3)."""
    return f0 + (1.0 - f0) * (1.0 - np.clip(cos_i, 0.0, 1.0))[:, None] ** 5


def f0_to_eta(f0: np.ndarray) -> np.ndarray:
    root = np.sqrt(np.clip(f0, 0.0, 0.999))
    return (1.0 + root) / (1.0 - root)


@dataclass(frozen=True)
class SurfaceSplit:
    """What a surface does with the feature path: write here, or pass on reflected / refracted weight."""

    features_here: np.ndarray  # bool (N,)
    reflect: np.ndarray  # (N, 3) throughput factor of the mirror direction
    refract: np.ndarray  # (N, 3) throughput factor of the refracted direction (0 where none)
    cos_t: np.ndarray  # (N,) refracted cosine (for the direction)
    eta: np.ndarray  # (N,) relative IOR across the surface along the ray


def split_surface(lobes: SurfaceLobes, base: np.ndarray, cos_i: np.ndarray, inside: np.ndarray) -> SurfaceSplit:
    """Cycles' rule (module docstring) at surfaces with ``base`` color (N x 3), hit with incidence cosine
    ``cos_i`` (N,), from inside the object where ``inside``."""
    m, t = lobes.metallic[:, None], lobes.transmission[:, None]
    f_s, _ = dielectric_fresnel(cos_i, f0_to_eta(lobes.specular_f0))
    eta = np.where(inside, 1.0 / lobes.ior, lobes.ior)
    f_g, cos_t = dielectric_fresnel(cos_i, eta)
    diffuse = (1 - m) * (1 - t) * (1 - f_s)[:, None] * base
    coat = (1 - m) * (1 - t) * f_s[:, None] * np.ones_like(base)
    metal = m * schlick(base, cos_i)
    glass_reflect = (1 - m) * t * f_g[:, None] * np.ones_like(base)
    glass_refract = (1 - m) * t * (1 - f_g)[:, None] * base
    specular = coat.mean(1) + metal.mean(1) + glass_reflect.mean(1) + glass_refract.mean(1)
    total = diffuse.mean(1) + specular
    nonspecular = diffuse.mean(1) + np.where(lobes.specular_like, 0.0, specular)
    here = (total <= 0) | (nonspecular > NONSPECULAR_SHARE * total)
    go = (~here)[:, None]
    return SurfaceSplit(here, np.where(go, coat + metal + glass_reflect, 0.0), np.where(go, glass_refract, 0.0),
                        cos_t, eta)
