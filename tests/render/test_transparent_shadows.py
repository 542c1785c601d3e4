"""Shadows of alpha (cut-out / BLEND) surfaces are transparent where alpha is 0, as in Cycles.

A diffuse floor (albedo rho) under a sun of irradiance E shining straight down shows rho E / pi where lit
(direct light only: 0 bounces) and 0 in a full shadow. A plane at z = 1 whose alpha map is 0 on its -x
half and 1 on its +x half shadows only the +x half of the floor below it; a BLEND plane of constant alpha a
lets (1 - a) of the light through. With an area light (found by both light sampling and BSDF sampling,
MIS-weighted), an all-transparent occluder leaves the floor as bright as no occluder at all (the two
estimators still sum to one through the null surface).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

RHO, SUN = 0.5, 2.0
LIT = RHO * SUN / math.pi
CAM2WORLD = hg.look_at([0.0, -2.5, 0.6], [0.0, 0.0, 0.0])
K = np.array([[30.0, 0, 19.5], [0, 30.0, 11.5], [0, 0, 1]])


def _variants() -> list[str]:
    best = choose_variant()
    return [best] if best == "scalar_rgb" else [best, "scalar_rgb"]


def _square(name: str, z: float, size: float, material: hg.Material) -> hg.MeshObject:
    h = size / 2
    vertices = [[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]]
    return hg.MeshObject(name, vertices, [[0, 1, 2], [0, 2, 3]], uvs=[[0, 0], [1, 0], [1, 1], [0, 1]],
                         material=material)


def _render(variant: str, occluder: hg.Material | None, *, sun: bool = True, spp: int = 8) -> tuple[np.ndarray,
                                                                                                     np.ndarray]:
    """Radiance (H x W x 3) and the world x of the floor point seen in each pixel (nan off the floor)."""
    scene = hg.Scene()
    scene.world.strength = 0.0
    scene.add(_square("floor", 0.0, 6.0, hg.Material(base_color=(RHO, RHO, RHO, 1), specular=0.0)))
    if occluder is not None:
        scene.add(_square("occluder", 1.0, 2.0, occluder))
    if sun:
        scene.add_light(hg.Light("sun", "SUN", energy=SUN, local2world=np.eye(4)))
    else:
        panel = _square("panel", 2.0, 4.0, hg.Material(base_color=(0, 0, 0, 1), specular=0.0,
                                                        emission=(1, 1, 1), emission_strength=3.0))
        scene.add(panel)
    scene.camera.intrinsics = hg.Intrinsics(K, 40, 24)
    settings = PathTraceSettings(samples=spp, max_bounces=0 if sun else 1, filter_width=0)
    image = PathTraceView(scene, settings, variant=variant).render(CAM2WORLD, seed=5)
    u, v = np.meshgrid(np.arange(40.0), np.arange(24.0))
    d = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1) @ CAM2WORLD[:3, :3].T
    t = -CAM2WORLD[2, 3] / d[..., 2]
    x = np.where(t > 0, CAM2WORLD[0, 3] + t * d[..., 0], np.nan)
    y = CAM2WORLD[1, 3] + t * d[..., 1]
    x[(np.abs(y) > 0.5) | (t <= 0)] = np.nan  # floor under the occluder's middle (pixel footprints inside it)
    return image, x


@pytest.mark.parametrize("variant", _variants())
def test_cut_out_lets_the_sun_through_where_alpha_is_zero(variant):
    alpha = np.zeros((4, 64), np.uint8)
    alpha[:, 32:] = 255  # +x half opaque (u > 0.5); texels of 3 cm
    clip = hg.Material(base_color=(0.8, 0.8, 0.8, 1), specular=0.0, alpha_texture=alpha, alpha_mode="CLIP")
    image, x = _render(variant, clip)
    under_hole = (x > -0.85) & (x < -0.15)
    under_solid = (x > 0.2) & (x < 0.8)
    assert under_hole.sum() > 20 and under_solid.sum() > 20
    np.testing.assert_allclose(image[under_hole].mean(axis=0), LIT, rtol=0.03)
    assert np.abs(image[under_hole] - LIT).max() < 0.05 * LIT  # every pixel, not just the mean
    assert image[under_solid].max() < 1e-4  # alpha 1: a full shadow
    outside = np.isfinite(x) & (np.abs(x) > 1.2)
    np.testing.assert_allclose(image[outside].mean(axis=0), LIT, rtol=0.03)


@pytest.mark.parametrize("variant", _variants())
def test_blend_alpha_transmits_one_minus_alpha(variant):
    blend = hg.Material(base_color=(0.8, 0.8, 0.8, 1), specular=0.0, alpha=0.3)
    image, x = _render(variant, blend)
    under = np.isfinite(x) & (np.abs(x) < 0.8)
    np.testing.assert_allclose(image[under].mean(axis=0), 0.7 * LIT, rtol=0.03)


def test_area_light_through_a_fully_transparent_surface_is_not_counted_twice():
    variant = choose_variant()
    invisible = hg.Material(base_color=(0.8, 0.8, 0.8, 1), specular=0.0, alpha=0.0)
    seen, x = _render(variant, invisible, sun=False, spp=64)
    free, _ = _render(variant, None, sun=False, spp=64)
    under = np.isfinite(x) & (np.abs(x) < 0.8)
    assert free[under].mean() > 0.1
    np.testing.assert_allclose(seen[under].mean(), free[under].mean(), rtol=0.03)
