"""PBR maps in Mitsuba: parameters of the converted BSDF, and normal / bump maps against analytic shading.

A Lambertian plane of albedo rho lit by a sun of irradiance E from direction l shows radiance
rho / pi * E * max(0, n_s . l), n_s the shading normal. A constant tangent-space normal map t gives
n_s = t_x dP/du + t_y (n x dP/du) + t_z n (OpenGL convention: +y along +v); a DirectX map inverts t_y. A
linear height ramp h(u) = u displaced by (h - 0.5) * scale metres tilts the normal by atan(scale * dh/dx).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

ALBEDO, SUN = 0.5, 3.0


@pytest.fixture(scope="module")
def variant() -> str:
    return choose_variant()


def _plane(material: hg.Material, size: float = 2.0, uv_repeats: float = 1.0) -> hg.MeshObject:
    """A square in z = 0 centred at the origin, UV u along +x and v along +y (0..uv_repeats)."""
    h = size / 2
    vertices = [[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]]
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float) * uv_repeats
    return hg.MeshObject("plane", vertices, [[0, 1, 2], [0, 2, 3]], uvs=uvs, material=material)


def _sun_pose(towards: np.ndarray) -> np.ndarray:
    """A pose whose +z axis is ``towards`` (a SUN shines along its -z)."""
    z = towards / np.linalg.norm(towards)
    x = np.cross([0.0, 1.0, 0.3], z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    return pose


def _radiance(variant: str, material: hg.Material, towards_light, uv_repeats: float = 1.0) -> np.ndarray:
    """Mean radiance of the centre pixels of the plane seen from straight above."""
    scene = hg.Scene()
    scene.add(_plane(material, uv_repeats=uv_repeats))
    scene.world.strength = 0.0
    scene.add_light(hg.Light("sun", "SUN", energy=SUN, local2world=_sun_pose(np.asarray(towards_light, float))))
    K = np.array([[40.0, 0, 7.5], [0, 40.0, 7.5], [0, 0, 1]])
    scene.camera.intrinsics = hg.Intrinsics(K, 16, 16)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 3.0], [0, 0, 0, 1]]))
    image = PathTraceView(scene, PathTraceSettings(samples=4, max_bounces=1), variant=variant).render(
        scene.camera.keypoints[0], seed=1)
    return image[4:12, 4:12].reshape(-1, 3).mean(axis=0)


def _lambert(normal: np.ndarray, towards_light) -> float:
    light = np.asarray(towards_light, float) / np.linalg.norm(towards_light)
    return ALBEDO / math.pi * SUN * max(0.0, float(normal @ light))


def _normal_map(tangent_normal) -> tuple[np.ndarray, np.ndarray]:
    """A 4x4 uint8 map of a constant tangent-space normal, and the normal its 8-bit codes decode to."""
    t = np.asarray(tangent_normal, float) / np.linalg.norm(tangent_normal)
    code = np.rint((t * 0.5 + 0.5) * 255).astype(np.uint8)
    decoded = code / 255.0 * 2 - 1
    return np.tile(code, (4, 4, 1)), decoded / np.linalg.norm(decoded)


def _diffuse(**maps) -> hg.Material:
    return hg.Material(base_color=(ALBEDO, ALBEDO, ALBEDO, 1.0), specular=0.0, **maps)


def test_roughness_and_metallic_values_and_maps_become_principled_parameters(variant):
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_variant import is_jit
    from hybridgen.render.pathtrace.principled_bsdf import PLUGIN_NAME

    mi.set_variant(variant)
    valued = bsdf_dict(hg.Material(roughness=0.25, metallic=0.75, specular=0.4), "o")
    # JIT variants: hybridgen's Principled BSDF (two-sided by itself); scalar_rgb: Mitsuba's, in twosided
    plugin = valued["type"] == PLUGIN_NAME
    assert plugin == is_jit(variant)
    principled = valued if plugin else valued["material"]
    assert principled["type"] == (PLUGIN_NAME if plugin else "principled")
    # roughness is wrapped for Cycles' filter glossy in the JIT variants (render/pathtrace/glossy_filter.py)
    wrapped = isinstance(principled["roughness"], dict)
    roughness = principled["roughness"]["value"] if wrapped else principled["roughness"]
    assert (roughness, principled["metallic"], principled["specular"]) == (0.25, 0.75, 0.4)
    prefix = "" if plugin else "brdf_0."
    params = mi.traverse(mi.load_dict(valued))
    if plugin:  # values are constants of the plugin; the glossy filter's wrapper holds the roughness
        assert float(params["roughness.value"][0]) == pytest.approx(0.25)
    else:
        assert float(params["brdf_0.roughness.value"][0]) == pytest.approx(0.25)
        assert float(params["brdf_0.metallic.value"][0]) == pytest.approx(0.75)
    ramp = np.array([[0, 64], [128, 255]], np.uint8)
    mapped = bsdf_dict(hg.Material(roughness_texture=ramp, metallic_texture=ramp[::-1]), "o")
    params = mi.traverse(mi.load_dict(mapped))
    np.testing.assert_allclose(np.array(params[prefix + "roughness" + (".map" if wrapped else "") + ".data"]).ravel(),
                               ramp.ravel() / 255.0, atol=1e-6)
    np.testing.assert_allclose(np.array(params[prefix + "metallic.data"]).ravel(), ramp[::-1].ravel() / 255.0,
                               atol=1e-6)
    # a metallic map alone makes the material principled even though its metallic value is 0
    metal = bsdf_dict(hg.Material(specular=0.0, metallic_texture=ramp), "o")
    assert (metal if plugin else metal["material"])["type"] == principled["type"]


def test_alpha_blend_and_clip_opacity(variant):
    import mitsuba as mi

    mi.set_variant(variant)
    assert bsdf_dict(hg.Material(alpha=0.3), "o")["opacity"] == 0.3
    assert bsdf_dict(hg.Material(alpha=0.3, alpha_mode="CLIP"), "o")["opacity"] == 0.0
    assert bsdf_dict(hg.Material(alpha=0.7, alpha_mode="CLIP"), "o")["type"] != "mask"  # clipped to opaque
    alpha = np.array([[10, 127], [128, 250]], np.uint8)
    for mode, expected in (("BLEND", alpha / 255.0), ("CLIP", (alpha / 255.0 >= 0.5).astype(float))):
        params = mi.traverse(mi.load_dict(bsdf_dict(hg.Material(alpha_texture=alpha, alpha_mode=mode), "o")))
        np.testing.assert_allclose(np.array(params["opacity.data"]).ravel(), expected.ravel(), atol=1e-6)


def test_roughness_changes_the_spread_of_the_highlight(variant):
    """A glossy plane under a sun seen at the mirror direction: roughness 0.05 concentrates the reflected
    sun in few pixels, roughness 1 spreads it - the brightest-to-mean ratio differs by a large factor."""
    towards = np.array([0.0, 0.0, 1.0])
    ratios = []
    for roughness in (0.15, 1.0):
        material = hg.Material(base_color=(0.2, 0.2, 0.2, 1), roughness=roughness, metallic=1.0)
        scene = hg.Scene()
        scene.add(_plane(material, size=6.0))
        scene.world.strength = 0.0
        scene.add_light(hg.Light("sun", "SUN", energy=SUN, local2world=_sun_pose(towards)))
        K = np.array([[20.0, 0, 15.5], [0, 20.0, 15.5], [0, 0, 1]])
        scene.camera.intrinsics = hg.Intrinsics(K, 32, 32)
        scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 2.0], [0, 0, 0, 1]]))
        image = PathTraceView(scene, PathTraceSettings(samples=8, max_bounces=1), variant=variant).render(
            scene.camera.keypoints[0], seed=1).mean(axis=2)
        # the sun reflects into the camera only at normal incidence: centre pixel vs the image's rim
        ratios.append(image[15:17, 15:17].mean() / max(image[0:3].mean(), 1e-6))
    assert ratios[0] > 3 * ratios[1], ratios


@pytest.mark.parametrize("towards_light", [(0.94, 0.0, 0.34), (-0.6, 0.0, 0.8), (0.0, 0.8, 0.6), (0.0, -0.8, 0.6)])
def test_constant_normal_map_shades_like_the_tilted_normal(variant, towards_light):
    tilt = math.radians(30)
    code, along_u = _normal_map([math.sin(tilt), 0.0, math.cos(tilt)])
    flat = _radiance(variant, _diffuse(), towards_light)
    np.testing.assert_allclose(flat, _lambert(np.array([0.0, 0, 1]), towards_light), rtol=0.01)
    tilted_u = _radiance(variant, _diffuse(normal_texture=code), towards_light)
    np.testing.assert_allclose(tilted_u, _lambert(along_u, towards_light), rtol=0.01, atol=1e-4)
    code_v, along_v = _normal_map([0.0, math.sin(tilt), math.cos(tilt)])
    tilted_v = _radiance(variant, _diffuse(normal_texture=code_v), towards_light)
    np.testing.assert_allclose(tilted_v, _lambert(along_v, towards_light), rtol=0.01, atol=1e-4)
    # the same image read as a DirectX map tilts towards -v
    directx = _radiance(variant, _diffuse(normal_texture=code_v, normal_y_down=True), towards_light)
    mirrored = along_v * np.array([1.0, -1.0, 1.0])
    np.testing.assert_allclose(directx, _lambert(mirrored, towards_light), rtol=0.01, atol=1e-4)


def test_displacement_ramp_shades_like_its_slope(variant):
    """Height h = u on a 2 m plane with UVs 0..1 and displacement_scale s: the displaced surface rises s / 2
    metres per metre along +x, so its normal is (-s/2, 0, 1) normalised."""
    ramp = np.tile(np.linspace(0, 255, 64).round().astype(np.uint8), (8, 1))  # u runs along the columns
    scale = 0.8
    # bilinear texels: h goes 0..1 between the first and last texel centres, 63/64 of u's range = 2 * 63/64 m
    slope = scale / (2 * 63 / 64)
    towards = (0.6, 0.0, 0.8)
    shaded = _radiance(variant, _diffuse(displacement_texture=ramp, displacement_scale=scale), towards)
    normal = np.array([-slope, 0.0, 1.0]) / math.hypot(slope, 1.0)
    np.testing.assert_allclose(shaded, _lambert(normal, towards), rtol=0.01)
    assert shaded.mean() < _lambert(np.array([0.0, 0, 1]), towards) * 0.97  # it does tilt away from the light
