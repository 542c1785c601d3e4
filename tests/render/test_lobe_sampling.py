"""Mitsuba's principled BSDFs choose their specular / diffuse lobe by albedo (render/pathtrace/lobe_sampling.py): rates as
documented, the same image on average, less noise. That BSDF renders in scalar_rgb and with HYBRIDGEN_PRINCIPLED=mitsuba
(hybridgen's own Principled BSDF picks its lobes by albedo itself), so these tests ask for it."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace import lobe_sampling, mitsuba_materials, path_trace
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.render.pathtrace.principled_material import ENV_VARIABLE


def _material(**values: float) -> hg.Material:
    material = hg.Material(name="m", base_color=(0.75, 0.2, 0.15, 1.0))
    for key, value in values.items():
        setattr(material, key, value)
    return material


def test_rates_follow_the_lobes_albedos(monkeypatch):
    monkeypatch.setenv(ENV_VARIABLE, "mitsuba")
    material = _material(specular=0.5, roughness=0.2)
    rates = lobe_sampling.principled_sampling_rates(material, 0.5)
    luminance = float(lobe_sampling.LUMINANCE @ np.array([0.75, 0.2, 0.15]))
    f_avg = 0.04 + 0.96 / 21
    share = rates["main_specular_sampling_rate"] / (rates["main_specular_sampling_rate"]
                                                   + rates["diffuse_reflectance_sampling_rate"])
    assert share == pytest.approx(f_avg / (f_avg + luminance * (1 - f_avg)))
    assert 0.15 < share < 0.3  # Mitsuba's own rates give 0.5
    assert lobe_sampling.principled_sampling_rates(_material(metallic=1.0), 0.5) == {}  # one lobe
    assert lobe_sampling.principled_sampling_rates(_material(transmission=1.0), 0.5) == {}  # Mitsuba's
    dark = lobe_sampling.principled_sampling_rates(_material(base_color=(0.0, 0.0, 0.0, 1.0)), 0.5)
    assert dark["main_specular_sampling_rate"] == pytest.approx(0.95 / 0.05)  # capped at 95 %
    textured = _material()
    textured.base_color_texture = np.full((4, 4, 3), 188, np.uint8)  # sRGB 188 = linear 0.5
    assert lobe_sampling.base_luminance(textured) == pytest.approx(0.5, abs=0.003)
    assert mitsuba_materials.bsdf_dict(material, "o")["material"]["main_specular_sampling_rate"] == \
        rates["main_specular_sampling_rate"]


def test_albedo_rates_keep_the_mean_and_lower_the_noise(monkeypatch):
    """A plastic-like plane under a constant sky (the only emitter: light and BSDF samples, MIS), direct light
    only, independent samples: Mitsuba's 50/50 lobe choice vs albedo rates."""
    variant = choose_variant(None)
    monkeypatch.setenv(ENV_VARIABLE, "mitsuba")
    monkeypatch.setattr(path_trace, "SAMPLER", "independent")
    scene = hg.Scene()
    plane = hg.make_primitive("plane", 50.0, name="plane", category_id=1, color=(0.75, 0.2, 0.15))
    plane.material.specular, plane.material.roughness = 0.5, 0.3
    scene.add(plane)
    scene.world.color, scene.world.strength = (1.0, 1.0, 1.0), 1.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.3, 16, 16)
    scene.camera.add_keypoint(hg.look_at([0.0, -2.0, 2.0], [0, 0, 0]))

    def noise_and_mean() -> tuple[float, float]:
        view = PathTraceView(scene, PathTraceSettings(samples=64, max_bounces=0, filter_width=0.0), variant=variant)
        a, b = view.render(scene.camera.keypoints[0], seed=1), view.render(scene.camera.keypoints[0], seed=2)
        return float(np.std(a - b)), float((a + b).mean() / 2)

    noise_albedo, mean_albedo = noise_and_mean()
    monkeypatch.setattr(mitsuba_materials, "principled_sampling_rates", lambda material, specular: {})
    noise_default, mean_default = noise_and_mean()
    assert mean_albedo == pytest.approx(mean_default, rel=0.01)
    assert noise_albedo < 0.8 * noise_default
