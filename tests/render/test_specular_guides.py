"""Denoising guides through sharp glass and mirrors (hybridgen/render/pathtrace/specular_guides.py), against analytic
Fresnel values: behind a smooth glass slab or a smooth metal mirror the guide albedo is the plane behind times
the specular throughput, and the guide normal is that plane's; rough surfaces keep the raster guides bit for bit."""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.denoise_guides import DEFAULT_FACTOR, DenoiseGuides
from hybridgen.render.pixel_filter import DEFAULT_WIDTH, filter_supersampled
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.render.pathtrace.specular_guides import (SurfaceLobes, can_be_specular_like, dielectric_fresnel, schlick,
                                              split_surface)

TARGET = (0.2, 0.5, 0.7)


@pytest.fixture(scope="module")
def jit_variant() -> str:
    variant = choose_variant()
    if not is_jit(variant):
        pytest.skip("traced guides need a JIT Mitsuba variant")
    return variant


def test_dielectric_fresnel_matches_textbook_values():
    f, cos_t = dielectric_fresnel(np.array([1.0, math.cos(math.atan(1.5)), 0.5]), np.array([1.5, 1.5, 1 / 1.5]))
    assert f[0] == pytest.approx(0.04, abs=1e-12)  # ((1 - 1.5) / (1 + 1.5))^2 at normal incidence
    r_s = ((math.cos(math.atan(1.5)) - 1.5 * cos_t[1]) / (math.cos(math.atan(1.5)) + 1.5 * cos_t[1])) ** 2
    assert f[1] == pytest.approx(r_s / 2, rel=1e-9)  # Brewster's angle: r_p = 0
    assert f[2] == 1.0 and cos_t[2] == 0.0  # 60 degrees inside glass: total internal reflection (critical 41.8)


def _lobes(**values: float) -> SurfaceLobes:
    material = hg.Material(**values)
    return SurfaceLobes.of([material])


def test_cycles_quarter_rule_decides_where_features_are_written():
    cos = np.array([1.0])
    black_coat = split_surface(_lobes(roughness=0.0, specular=0.5, metallic=0.0), np.zeros((1, 3)), cos,
                               np.array([False]))
    assert not black_coat.features_here[0]  # all weight in the sharp specular layer: look through
    np.testing.assert_allclose(black_coat.reflect[0], 0.04)  # F0 = 0.08 x specular
    white_coat = split_surface(_lobes(roughness=0.0, specular=0.5), np.full((1, 3), 0.8), cos, np.array([False]))
    assert white_coat.features_here[0]  # diffuse 0.8 x 0.96 of 0.808 > 1/4
    assert not can_be_specular_like(hg.Material(roughness=0.3, metallic=1.0))  # alpha 0.09 > 0.075
    assert can_be_specular_like(hg.Material(roughness=0.27, metallic=1.0))  # alpha 0.0729
    assert not can_be_specular_like(hg.Material(roughness=0.0, specular=0.0))  # Lambertian


def _interior(shape: tuple[int, int], border: int = 3) -> tuple[slice, slice]:
    return slice(border, shape[0] - border), slice(border, shape[1] - border)


def _filtered(scene: hg.Scene, value) -> np.ndarray:
    """``value(rays)`` (H x W x C from unit world-axes camera rays, H x W x 3) evaluated at the guides' 3 x 3
    sub-pixel centres and filtered with the color's pixel filter, as the guides are."""
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    fine = intr.resized(intr.width * DEFAULT_FACTOR, intr.height * DEFAULT_FACTOR)
    v, u = np.mgrid[0:fine.height, 0:fine.width] + 0.5
    rays = np.linalg.solve(fine.K, np.stack([u.ravel(), v.ravel(), np.ones(u.size)])).T @ pose[:3, :3].T
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    return filter_supersampled(value(rays.reshape(fine.height, fine.width, 3)), DEFAULT_FACTOR, DEFAULT_WIDTH)


def _guides(scene: hg.Scene, variant: str, **settings: int) -> tuple[tuple[np.ndarray, np.ndarray],
                                                                     tuple[np.ndarray, np.ndarray], int]:
    view = PathTraceView(scene, PathTraceSettings(samples=1, **settings), variant=variant)
    guides = DenoiseGuides(scene, filter_width=view.filter_width, follow_specular=True)
    try:
        pose = scene.camera.keypoints[0]
        raster, traced = guides.render(pose), guides.render(pose, view)
        again = guides.render(pose, view)
        for a, b in zip(traced, again):  # deterministic
            np.testing.assert_array_equal(a, b)
        return raster, traced, guides.traced_subpixels
    finally:
        guides.release()


def _slab_scene(roughness: float) -> hg.Scene:
    """A 20 x 20 x 0.2 m glass slab (IOR 1.5) over a Lambertian floor, seen from above at ~50 degrees."""
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 40.0, name="floor", category_id=1, color=TARGET)
    floor.material.specular = 0.0
    scene.add(floor)
    slab = hg.make_primitive("cube", 1.0, name="slab", category_id=2, color=(1.0, 1.0, 1.0),
                             local2world=hg.object_pose([0, 0, 1.0]) @ np.diag([20.0, 20.0, 0.2, 1.0]))
    slab.material.transmission, slab.material.roughness, slab.material.ior = 1.0, roughness, 1.5
    scene.add(slab)
    scene.world.color = (0.0, 0.0, 0.0)  # the reflected branches escape and add nothing
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.5, 48, 36, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.0, -2.5, 3.0], [0.0, 0.0, 1.0]))
    return scene


def test_guides_behind_smooth_glass_are_the_floor_times_the_fresnel_transmittance(gl_context, jit_variant):
    scene = _slab_scene(roughness=0.0)
    raster, (albedo, normals), traced = _guides(scene, jit_variant)
    assert traced == albedo.shape[0] * albedo.shape[1] * 9  # every sub-pixel sees the slab
    np.testing.assert_allclose(raster[0][_interior(albedo.shape[:2])], 1.0, atol=1e-6)  # raster: the glass itself
    # a parallel slab: the same angle at both faces, so (1 - F(theta))^2 passes; the reflections escape (black)
    transmitted = _filtered(scene,
                            lambda rays: (1.0 - dielectric_fresnel(np.abs(rays[..., 2:]), np.array(1.5))[0]) ** 2)
    inner = _interior(albedo.shape[:2])
    np.testing.assert_allclose(albedo[inner], (transmitted * np.array(TARGET))[inner], rtol=1e-4)
    floor_normal = scene.camera.keypoints[0][:3, :3].T @ np.array([0.0, 0.0, 1.0])  # camera axes
    np.testing.assert_allclose(normals[inner], (transmitted * floor_normal)[inner], atol=1e-4)
    assert 0.8 < transmitted.min() and transmitted.max() < 0.93  # the Fresnel factor is really tested


def test_rough_glass_keeps_the_raster_guides_bit_for_bit(gl_context, jit_variant):
    raster, traced, count = _guides(_slab_scene(roughness=0.3), jit_variant)  # GGX alpha 0.09 > 0.075
    assert count == 0
    for a, b in zip(raster, traced):
        np.testing.assert_array_equal(a, b)


def test_guides_in_a_smooth_metal_mirror_are_the_wall_times_schlick_and_rough_pixels_stay(gl_context, jit_variant):
    mirror_color = (0.9, 0.6, 0.3)
    scene = hg.Scene()
    mirror = hg.make_primitive("plane", 40.0, name="mirror", category_id=1, color=mirror_color)
    mirror.material.metallic, mirror.material.roughness = 1.0, 0.0
    scene.add(mirror)
    wall = hg.make_primitive("plane", 40.0, name="wall", category_id=2, color=TARGET,
                             local2world=hg.object_pose([0.0, 6.0, 0.0], [math.pi / 2, 0.0, 0.0]))
    wall.material.specular = 0.0
    scene.add(wall)
    rough = hg.make_primitive("cube", 0.3, name="rough", category_id=3, color=(0.3, 0.8, 0.3),
                              local2world=hg.object_pose([0.0, 0.0, 0.15]))
    rough.material.metallic, rough.material.roughness = 1.0, 0.6
    scene.add(rough)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.3, 64, 48, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.0, -3.0, 1.0], [0.0, 0.0, 0.2]))  # ~17 degrees above the mirror
    (raster_albedo, raster_normals), (albedo, normals), _ = _guides(scene, jit_variant)
    ids = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"]
    near = np.zeros(ids.shape, bool)  # pixels whose filter footprint (1.5 px) reaches another object
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            near |= np.roll(ids, (dy, dx), axis=(0, 1)) != ids
    inner = np.zeros(ids.shape, bool)
    inner[_interior(ids.shape)] = True
    mirror_px, rough_px = inner & ~near & (ids == mirror.instance_id), inner & ~near & (ids == rough.instance_id)
    assert mirror_px.sum() > 500 and rough_px.sum() > 20
    expected = _filtered(scene, lambda rays: schlick(np.tile(mirror_color, (rays.size // 3, 1)), np.abs(
        rays[..., 2].ravel())).reshape(rays.shape) * TARGET)
    camera = scene.camera.keypoints[0][:3, 3]

    def reflection_sees_the_cube(rays: np.ndarray) -> np.ndarray:  # slab test of the mirrored ray and the box
        start = camera + rays * (-camera[2] / rays[..., 2:])
        mirrored = rays * np.array([1.0, 1.0, -1.0])
        with np.errstate(divide="ignore"):
            t = (np.stack([np.full(3, -0.15), np.array([0.15, 0.15, 0.3])])[:, None, None] - start) / mirrored
        near_t, far_t = np.min(t, axis=0).max(axis=-1), np.max(t, axis=0).min(axis=-1)
        return (near_t <= far_t)[..., None].astype(float)

    mirror_px &= _filtered(scene, reflection_sees_the_cube)[..., 0] == 0
    assert mirror_px.sum() > 500
    np.testing.assert_allclose(albedo[mirror_px], expected[mirror_px], rtol=1e-4)
    assert np.abs(expected[mirror_px] - np.array(mirror_color) * TARGET).max() > 0.01  # the Fresnel term shows
    wall_normal = scene.camera.keypoints[0][:3, :3].T @ np.array([0.0, -1.0, 0.0])  # facing the reflected rays
    np.testing.assert_allclose(normals[mirror_px], np.broadcast_to(wall_normal, normals[mirror_px].shape), atol=1e-3)
    far = ~near & (ids != mirror.instance_id)  # rough pixels away from the mirror: raster values bit for bit
    np.testing.assert_array_equal(albedo[far], raster_albedo[far])
    np.testing.assert_array_equal(normals[far], raster_normals[far])


@pytest.mark.parametrize("follow", [False, True])
def test_color_producer_denoises_with_the_guides_of_its_own_path_trace_view(gl_context, jit_variant, monkeypatch,
                                                                            follow):
    """Off by default (denoise_guides.FOLLOW_SPECULAR: measured neutral); on, the producer's own view is traced."""
    pytest.importorskip("pyoidn")
    from hybridgen.render import denoise_guides
    from hybridgen.render.render_color import ColorProducer

    assert denoise_guides.FOLLOW_SPECULAR is False
    monkeypatch.setattr(denoise_guides, "FOLLOW_SPECULAR", follow)
    scene = _slab_scene(roughness=0.0)
    scene.lights.append(hg.Light("sun", "SUN", energy=2.0, local2world=hg.object_pose([0, 0, 5], [0.3, 0.1, 0])))
    producer = ColorProducer(scene, PathTraceSettings(samples=1), variant=jit_variant, denoise=True)
    try:
        producer.produce(0, scene.camera.keypoints[0])
        intr = scene.camera.intrinsics
        assert producer.guides is not None
        assert producer.guides.traced_subpixels == (intr.width * intr.height * 9 if follow else 0)
    finally:
        producer.close()


def test_past_the_glossy_bounce_limit_a_mirror_shows_only_what_emits(gl_context, jit_variant):
    """glossy_bounces 0 (BlenderProc's): the path tracer ends after the mirror bounce but still adds the emission
    it hits, as Cycles adds it to its denoising albedo (with no features): an emitting wall shows in the guide
    albedo times Schlick's F, a plain one not at all; no normal either way."""
    results = []
    for emitting in (True, False):
        scene = hg.Scene()
        mirror = hg.make_primitive("plane", 40.0, name="mirror", category_id=1, color=(0.9, 0.6, 0.3))
        mirror.material.metallic, mirror.material.roughness = 1.0, 0.0
        scene.add(mirror)
        wall = hg.make_primitive("plane", 40.0, name="wall", category_id=2, color=TARGET,
                                 local2world=hg.object_pose([0.0, 6.0, 0.0], [math.pi / 2, 0.0, 0.0]))
        wall.material.specular = 0.0
        if emitting:
            wall.material.emission, wall.material.emission_strength = (1.0, 1.0, 1.0), 2.0
        scene.add(wall)
        scene.world.color = (0.0, 0.0, 0.0)
        scene.camera.intrinsics = hg.Intrinsics.from_fov(0.3, 32, 24, clip_start=0.01)
        scene.camera.add_keypoint(hg.look_at([0.0, -3.0, 1.0], [0.0, 0.0, 0.2]))
        results.append(_guides(scene, jit_variant, glossy_bounces=0)[1])
    (albedo, normals), (dark_albedo, dark_normals) = results
    inner = _interior(albedo.shape[:2])
    expected = _filtered(scene, lambda rays: schlick(np.tile((0.9, 0.6, 0.3), (rays.size // 3, 1)), np.abs(
        rays[..., 2].ravel())).reshape(rays.shape) * TARGET)
    np.testing.assert_allclose(albedo[inner], expected[inner], rtol=1e-4)
    np.testing.assert_array_equal(dark_albedo[inner], 0.0)
    np.testing.assert_array_equal(normals[inner], 0.0)
    np.testing.assert_array_equal(dark_normals[inner], 0.0)
