"""Blender's procedural textures (hybridgen.scene.procedural_texture) against Blender 4.2, measured with bpy 4.2
(``bpy.data.textures.new(name, type).evaluate(point)``; tools/blender_textures.py prints the whole comparison):
exact values where the texture is a formula (BLEND, WOOD, MAGIC at depth 0), and for the noise textures the
statistics of 4000 random points in [-12, 12]^3 - range, mean, spread and the correlation at a shift along x,
which is what "feature size = noise_scale" means."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.scene.procedural_texture import displacement_value, evaluate, settings_of

POINTS = [(-2, 0.3, 0.1), (-0.5, 0.3, 0.1), (0.2, -0.4, 0.7), (0.6, 0.5, -0.2), (1.5, 0.1, 0.1), (0.3, 1.7, 0.2),
          (-0.3, -0.6, 0)]
BLENDER_BLEND = {
    ("LINEAR", "HORIZONTAL"): [-0.5, 0.25, 0.6, 0.8, 1.25, 0.65, 0.35],
    ("LINEAR", "VERTICAL"): [0.65, 0.65, 0.3, 0.75, 0.55, 1.35, 0.2],
    ("QUADRATIC", "HORIZONTAL"): [0.0, 0.0625, 0.36, 0.64, 1.5625, 0.4225, 0.1225],
    ("EASING", "HORIZONTAL"): [0.0, 0.15625, 0.648, 0.896, 1.0, 0.71825, 0.28175],
    ("DIAGONAL", "HORIZONTAL"): [0.075, 0.45, 0.45, 0.775, 0.9, 1.0, 0.275],
    ("SPHERICAL", "HORIZONTAL"): [0.0, 0.408392, 0.169338, 0.193774, 0.0, 0.0, 0.32918],
    ("QUADRATIC_SPHERE", "HORIZONTAL"): [0.0, 0.166784, 0.028675, 0.037548, 0.0, 0.0, 0.108359],
    ("RADIAL", "HORIZONTAL"): [0.976303, 0.91399, 0.323792, 0.610571, 0.510595, 0.7222, 0.176208],
    ("RADIAL", "VERTICAL"): [0.273697, 0.33601, 0.926208, 0.639429, 0.739405, 0.5278, 0.073792],
}
"""Blender's BLEND intensities at POINTS per (progression, use_flip_axis)."""
FORMULA_POINTS = [(0.1, 0.2, 0.3), (0.5, -0.2, 0.05), (-0.7, 0.33, 0.9), (1.3, -0.4, -0.25)]
BLENDER_FORMULAS = {
    ("WOOD", ()): [0.360292, 0.324608, 0.083866, 0.60756],
    ("WOOD", (("wood_type", "RINGS"),)): [0.966043, 0.007982, 0.007854, 0.788766],
    ("MAGIC", (("noise_depth", 0),)): [0.553096, 0.525316, 0.454942, 0.566911],
}
BLENDER_STATISTICS = {
    # label: (type, changes, mean, std, q01, q99, correlation at x + 0.05, 0.1, 0.2, 0.3, 0.5 m)
    "CLOUDS": ("CLOUDS", {}, 0.503, 0.120, 0.238, 0.769, (0.796, 0.483, 0.074, -0.032, 0.001)),
    "CLOUDS scale 1": ("CLOUDS", {"noise_scale": 1.0, "noise_depth": 0}, 0.495, 0.182, 0.084, 0.882,
                       (0.993, 0.970, 0.884, 0.754, 0.439)),
    "DISTORTED_NOISE": ("DISTORTED_NOISE", {}, 0.000, 0.338, -0.754, 0.767, (0.655, 0.261, 0.034, 0.034, 0.019)),
    "MARBLE": ("MARBLE", {}, 0.500, 0.352, 0.000, 1.000, (0.905, 0.741, 0.405, 0.058, -0.545)),
    "MUSGRAVE": ("MUSGRAVE", {}, 1.000, 0.416, 0.206, 2.051, (0.819, 0.474, 0.041, -0.050, -0.007)),
    "STUCCI": ("STUCCI", {}, 0.503, 0.182, 0.103, 0.907, (0.893, 0.629, 0.091, -0.046, -0.025)),
    "VORONOI": ("VORONOI", {}, 0.518, 0.171, 0.124, 0.885, (0.812, 0.437, -0.012, -0.005, 0.011)),
    # MAGIC's folding is hybridgen's own: at half a period (0.5 m) Blender's is -0.265, hybridgen's -0.6
    "MAGIC": ("MAGIC", {}, 0.498, 0.217, 0.097, 0.972, (0.948, 0.810, 0.424, 0.059, None)),
    "NOISE": ("NOISE", {}, 0.123, 0.203, 0.000, 1.000, (0.016, 0.012, 0.031, -0.007, 0.019)),
}
LAGS = (0.05, 0.1, 0.2, 0.3, 0.5)


@pytest.mark.parametrize("key", list(BLENDER_BLEND))
def test_blend_gradients_equal_blenders(key: tuple) -> None:
    settings = {**settings_of("BLEND"), "progression": key[0], "use_flip_axis": key[1]}
    assert np.allclose(evaluate("BLEND", settings, np.array(POINTS))[0], BLENDER_BLEND[key], atol=2e-6)


@pytest.mark.parametrize("key", list(BLENDER_FORMULAS))
def test_formula_textures_equal_blenders(key: tuple) -> None:
    kind, changes = key
    settings = {**settings_of(kind), **dict(changes)}
    assert np.allclose(displacement_value(kind, settings, np.array(FORMULA_POINTS)), BLENDER_FORMULAS[key], atol=2e-6)


@pytest.mark.parametrize("label", list(BLENDER_STATISTICS))
def test_noise_statistics_follow_blenders(label: str) -> None:
    kind, changes, mean, std, q01, q99, correlation = BLENDER_STATISTICS[label]
    settings = {**settings_of(kind), **changes}
    points = np.random.default_rng(1).uniform(-12.0, 12.0, size=(4000, 3))
    values = displacement_value(kind, settings, points)
    assert values.mean() == pytest.approx(mean, abs=0.03) and values.std() == pytest.approx(std, rel=0.12)
    assert np.quantile(values, 0.01) == pytest.approx(q01, abs=0.06)
    assert np.quantile(values, 0.99) == pytest.approx(q99, abs=0.06)
    for lag, expected in zip(LAGS, correlation):
        if expected is None:
            continue
        shifted = displacement_value(kind, settings, points + np.array([lag, 0.0, 0.0]))
        assert np.corrcoef(values, shifted)[0, 1] == pytest.approx(expected, abs=0.08), lag


def test_clouds_range_and_feature_size_scale_with_noise_scale() -> None:
    points = np.random.default_rng(5).uniform(-20.0, 20.0, size=(6000, 3))
    coarse = {**settings_of("CLOUDS"), "noise_scale": 1.0}
    fine = settings_of("CLOUDS")  # noise_scale 0.25
    values = displacement_value("CLOUDS", fine, points)
    assert 0.0 <= values.min() and values.max() <= 1.0  # turbulence of one-octave values in [0, 1]
    for lag in (0.05, 0.1, 0.2):  # a shift of d at scale 0.25 correlates as one of 4 d at scale 1
        small = np.corrcoef(values, displacement_value("CLOUDS", fine, points + [lag, 0, 0]))[0, 1]
        scaled = np.corrcoef(displacement_value("CLOUDS", coarse, 4 * points),
                             displacement_value("CLOUDS", coarse, 4 * points + [4 * lag, 0, 0]))[0, 1]
        assert small == pytest.approx(scaled, abs=1e-9)
    bright = {**fine, "intensity": 1.3, "contrast": 2.0}  # Blender: mean 0.805, std 0.240 (0.503 and 0.120 before)
    assert np.allclose(displacement_value("CLOUDS", bright, points), (values - 0.5) * 2.0 + 0.8)
    clamped = {**bright, "use_clamp": True}
    assert displacement_value("CLOUDS", clamped, points).max() == 1.0
