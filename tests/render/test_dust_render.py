"""Dust films in the path tracer (render/pathtrace/dust_mix.py): the mix BSDF's albedo is the weighted sum of its
parts' (by sampling and by integrating eval; never above one for white parts: a furnace), its samples agree with
eval / pdf; a white furnace sphere stays exactly 1; a dusty up-facing Lambertian square under a sun renders as
(1 - w) base + w dust per pixel with w the analytic weight of hybridgen.scene.dust (so its mean color moves
toward the dust's by the mean weight, and the flakes lie where the UVs put them); strength 0 renders bit for bit
as no dust."""
from __future__ import annotations

import math

import numpy as np
import pytest

from hybridgen.scene.dust import DUST_COLOR, Dust, dust_weight, noise_pattern
from hybridgen.scene.gradient_noise import NUMPY
from hybridgen.scene.material import Material

SAMPLES = 1 << 17
BASE = (0.1, 0.2, 0.6)


@pytest.fixture
def mi(jit_variant: str):
    import mitsuba

    mitsuba.set_variant(jit_variant)
    return mitsuba


def _bsdf(mi, material: Material):
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    return mi.load_dict(bsdf_dict(material, "test", uvs=True))


def _interaction(mi, mu: float, uv: tuple[float, float], n: int):
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.n = mi.Vector3f(0.0, 0.0, 1.0)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(math.sqrt(1.0 - mu * mu), 0.0, mu)
    si.uv = mi.Point2f(uv[0], 1.0 - uv[1])
    return si


def _flake_uv() -> tuple[float, float]:
    """A UV point on a dust flake of texture scale 0.1 (pattern 1)."""
    u = np.linspace(0.01, 0.02, 200, dtype=np.float32)
    pattern = noise_pattern(NUMPY, u, np.full_like(u, 0.3), 0.1)
    return float(u[np.argmax(pattern == 1.0)]), 0.3


def _albedo(mi, bsdf, si) -> tuple[np.ndarray, float]:
    """Directional albedo by sampling (mean weight) and its standard error; checks each sample against eval_pdf."""
    rng = np.random.default_rng(0)
    ctx = mi.BSDFContext()
    s1, s2x, s2y = (mi.Float(rng.random(SAMPLES).astype(np.float32)) for _ in range(3))
    sample, weight = bsdf.sample(ctx, si, s1, mi.Point2f(s2x, s2y))
    value, pdf = bsdf.eval_pdf(ctx, si, sample.wo)
    ok = np.asarray(sample.pdf) > 0
    np.testing.assert_allclose(np.asarray(pdf)[ok], np.asarray(sample.pdf)[ok], rtol=1e-4)
    w = np.asarray(weight).T
    np.testing.assert_allclose(np.asarray(value).T[ok] / np.asarray(pdf)[ok, None], w[ok], rtol=1e-3, atol=1e-6)
    return w.mean(0), float(w[:, 0].std() / math.sqrt(SAMPLES))


def _eval_albedo(mi, bsdf, si_one) -> np.ndarray:
    """Directional albedo by integrating eval over a stratified grid of the upper hemisphere."""
    import drjit as dr

    cos_cells, phi_cells = 256, 512
    c, p = np.meshgrid((np.arange(cos_cells) + 0.5) / cos_cells, (np.arange(phi_cells) + 0.5) / phi_cells * 2 * np.pi)
    s = np.sqrt(1 - c * c)
    wo = mi.Vector3f(*(mi.Float(a.ravel().astype(np.float32)) for a in (s * np.cos(p), s * np.sin(p), c)))
    si = dr.zeros(mi.SurfaceInteraction3f, dr.width(wo))
    si.n, si.sh_frame, si.wi, si.uv = si_one.n, si_one.sh_frame, si_one.wi, si_one.uv
    value = np.asarray(bsdf.eval(mi.BSDFContext(), si, wo)).T
    return value.mean(0) * 2 * np.pi


@pytest.mark.parametrize("mu", [1.0, 0.5])
def test_mix_albedo_is_the_weighted_sum_and_never_above_one(mi, mu: float) -> None:
    uv = _flake_uv()
    white = Material(base_color=(1, 1, 1, 1), roughness=0.3, specular=0.5)
    nested, _ = _albedo(mi, _bsdf(mi, white), _interaction(mi, mu, uv, SAMPLES))
    for strength, color in ((0.5, DUST_COLOR), (1.0, (1.0, 1.0, 1.0)), (0.7, (0.2, 0.9, 0.4))):
        dusty = Material(base_color=(1, 1, 1, 1), roughness=0.3, specular=0.5, dust=(Dust(strength, color=color),))
        bsdf = _bsdf(mi, dusty)
        w = float(dust_weight(*np.float32([uv[0], uv[1], 1.0, mu]), Dust(strength)))
        assert w == pytest.approx(min(strength, 1.0))  # a flake on an up-facing surface: w = strength
        expected = (1 - w) * nested + w * np.asarray(color)
        albedo, error = _albedo(mi, bsdf, _interaction(mi, mu, uv, SAMPLES))
        np.testing.assert_allclose(albedo, expected, atol=4 * error + 2e-3)
        np.testing.assert_allclose(_eval_albedo(mi, bsdf, _interaction(mi, mu, uv, 1)), expected, rtol=0.01)
        assert np.all(albedo <= 1.0 + 4 * error)


def _square(material: Material, size: tuple[int, int] = (48, 48), down: bool = False):
    """A 2 m square at z = 0 with UV 0..1 over it, wound facing up (or down), lit straight from above."""
    import hybridgen as hg

    vertices = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    faces = np.array([[0, 2, 1], [0, 3, 2]]) if down else np.array([[0, 1, 2], [0, 2, 3]])
    scene = hg.Scene()
    scene.add(hg.MeshObject(name="square", vertices=vertices, faces=faces,
                            uvs=np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]), material=material))
    scene.world.strength = 0.0
    scene.add_light(hg.Light("sun", "SUN", energy=3.0, local2world=np.eye(4)))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.298, *size, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.0, -0.3, 6.0], [0.0, 0.0, 0.0]))
    return scene


def _render(scene, variant: str, spp: int = 64) -> np.ndarray:
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from tools.principled_vs_cycles import hybridgen_settings

    view = PathTraceView(scene, hybridgen_settings(1), variant=variant)
    return np.asarray(view.render(scene.camera.keypoints[0], seed=0, spp=spp), np.float64)


def _pixel_weights(scene, layer: Dust, sub: int = 4) -> np.ndarray:
    """Mean analytic dust weight over sub x sub points of each pixel of the square (rays cast here)."""
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    total = np.zeros((intr.height, intr.width))
    for dy in offsets:
        for dx in offsets:
            v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
            rays = np.stack([u + dx, v + dy, np.ones_like(u)], -1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
            rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
            t = -pose[2, 3] / rays[..., 2]
            x, y = pose[0, 3] + t * rays[..., 0], pose[1, 3] + t * rays[..., 1]
            f32 = [np.float32(a) for a in ((x + 1) / 2, (y + 1) / 2, np.ones_like(x), -rays[..., 2])]
            total += dust_weight(*f32, layer)
    return total / sub ** 2


@pytest.mark.parametrize("strength, down", [(1.0, False), (0.5, False), (1.0, True)])
def test_dusty_square_moves_toward_dust_by_the_weight(jit_variant: str, strength: float, down: bool) -> None:
    """(``down``: wound facing down but seen from above, the normal turned toward the viewer gets dust, as in
    Cycles.)"""
    layer = Dust(strength, texture_scale=20.0)  # 12.5 noise cells across: flakes several pixels wide
    scene = _square(Material(base_color=(*BASE, 1), specular=0.0, dust=(layer,)), down=down)
    image = _render(scene, jit_variant)
    w = _pixel_weights(scene, layer)[..., None]
    irradiance = 3.0 / math.pi
    expected = irradiance * ((1 - w) * np.asarray(BASE) + w * np.asarray(DUST_COLOR))
    np.testing.assert_allclose(image.mean((0, 1)), expected.mean((0, 1)), rtol=0.01)
    toward = (image[..., 0].mean() - irradiance * BASE[0]) / (irradiance * (DUST_COLOR[0] - BASE[0]))
    assert toward == pytest.approx(w.mean(), abs=0.01) and 0.1 < w.mean() < strength
    assert np.corrcoef(image[..., 0].ravel(), expected[..., 0].ravel())[0, 1] > 0.97  # flakes where the UVs say


def test_strength_zero_is_bit_identical(jit_variant: str) -> None:
    plain = _render(_square(Material(base_color=(*BASE, 1), roughness=0.4)), jit_variant, spp=16)
    for layers in ((Dust(0.0),), (Dust(0.0), Dust(-0.5, 0.05))):
        dusty = _render(_square(Material(base_color=(*BASE, 1), roughness=0.4, dust=layers)), jit_variant, spp=16)
        assert np.array_equal(plain, dusty)


def test_white_furnace(jit_variant: str) -> None:
    """A white Lambertian square in a uniform white world (a furnace: it reflects all it gets, mean radiance 1):
    white dust over it changes nothing (the mix of two white cosine lobes is one; per sample the two sides draw
    different directions, so the images agree within their noise: at 64 spp the means differ by 4e-5, the pixels
    by 0.006 on average); gray dust of albedo 0.5 scales each pixel by 1 - 0.5 x its mean weight."""
    def furnace(dust: tuple[Dust, ...]) -> tuple[np.ndarray, object]:
        scene = _square(Material(base_color=(1, 1, 1, 1), specular=0.0, dust=dust), (24, 24))
        scene.lights.clear()
        scene.world.color, scene.world.strength = (1.0, 1.0, 1.0), 1.0
        return _render(scene, jit_variant, spp=64), scene

    plain, _ = furnace(())
    assert abs(plain.mean() - 1.0) < 0.01
    white, _ = furnace((Dust(1.0, 20.0, color=(1.0, 1.0, 1.0)),))
    assert abs(white.mean() - plain.mean()) < 1e-3 and np.abs(white - plain).mean() < 0.015
    gray_layer = Dust(1.0, 20.0, color=(0.5, 0.5, 0.5))
    gray, scene = furnace((gray_layer,))
    expected = 1.0 - 0.5 * _pixel_weights(scene, gray_layer)
    ratio = gray[..., 0] / plain[..., 0]
    assert np.all(ratio <= 1.0 + 1e-5) and np.abs(ratio - expected).mean() < 0.02 and ratio.min() < 0.8


def test_scalar_variant_stops_with_one_line() -> None:
    import mitsuba

    from hybridgen.errors import InputError
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    previous = mitsuba.variant()
    mitsuba.set_variant("scalar_rgb")
    try:
        with pytest.raises(InputError, match="JIT variants only") as raised:
            bsdf_dict(Material(name="dusty", dust=(Dust(0.5),)), "square")
        assert "\n" not in str(raised.value)
        assert bsdf_dict(Material(name="clean", dust=(Dust(0.0),)), "square")["type"] == "twosided"
    finally:
        if previous:
            mitsuba.set_variant(previous)
