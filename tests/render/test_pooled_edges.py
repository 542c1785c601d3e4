"""hybridgen.render.pathtrace.pooled_edges: edge pixels' raw values from their own and their neighbours' samples.

The filter density is the Blackman-Harris window of hybridgen.render.pixel_filter, normalised. On a real render of
an emitting panel whose straight edge crosses the image (seen directly: every sample is the panel's radiance or 0,
so each column of pixels has one expected value), the pooled estimate agrees with the pixels' own means column by
column (the same expectation), is lower in noise along the edge, is exact where every sample agrees, and is the same
bytes on every run."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.render.pathtrace.pooled_edges import REACH, SHAPE, filter_density
from hybridgen.render.pixel_filter import blackman_harris
from hybridgen.render.tonemap import srgb_encode
from tests.render.test_edge_blend import _scene as edge_blend_scene

L = 1.5  # the panel's radiance
LOOK_UP = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.0], [0, 0, 0, 1]])  # at z = 1 looking up (+z)


def test_filter_density_is_the_normalised_pixel_filter() -> None:
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_variant import activate

    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    activate(variant)
    x = np.linspace(-2.6, 2.6, 1040)  # (not exactly on a support end, where float32 rounding decides)
    for width in (1.5, 1.0):
        for shift in (-2, -1, 0, 1, 2):
            got = np.asarray(filter_density(mi.Float(x.astype(np.float32)), width, shift), dtype=np.float64)
            window = blackman_harris(x - shift, width)
            np.testing.assert_allclose(got, window / (0.35875 * 2 * width), atol=2e-6)
        fine = np.linspace(-width, width, 200001)
        density = np.asarray(filter_density(mi.Float(fine.astype(np.float32)), width), dtype=np.float64)
        assert density.sum() * (fine[1] - fine[0]) == pytest.approx(1.0, abs=1e-4)
    assert len(REACH) == 13 and (0, 0) in REACH and all(abs(a) + abs(b) <= 2 for a, b in REACH)
    assert SHAPE[0] == (0, 0) and len(SHAPE) == 5


def _panel_scene(edge_x: float) -> hg.Scene:
    """A black panel emitting L, 1 m above a camera looking up; its right edge at world x = ``edge_x``."""
    scene = hg.Scene()
    scene.world.strength = 0.0
    panel = hg.make_primitive("plane", 3.0, name="panel", category_id=1, color=(0.0, 0.0, 0.0))
    half = float(np.max(panel.vertices[:, 0]))
    panel.local2world = hg.object_pose(location=[edge_x - half, 0.0, 2.0])
    panel.material.specular, panel.material.emission, panel.material.emission_strength = 0.0, (1.0, 1.0, 1.0), L
    scene.add(panel)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, 24, 96)
    return scene


def _render(view: PathTraceView) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pool = view.pooled_edges()
    assert pool is not None
    edges = np.ones((96, 24), bool)  # every pixel pooled
    linear, counts = view.render_with_counts(LOOK_UP, seed=7, edges=lambda: edges, pool=pool)
    assert pool.started
    return linear[..., 0].astype(np.float64), pool.image()[..., 0].astype(np.float64), counts


def test_pooled_estimate_keeps_the_expectation_and_is_exact_where_samples_agree() -> None:
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    scene = _panel_scene(edge_x=0.0123)  # the edge off the pixel grid, near the image's middle
    settings = PathTraceSettings(samples=64, noise_threshold=0.01, min_samples=8, edge_min_samples=64, max_bounces=0)
    view = PathTraceView(scene, settings, variant=variant)
    own, pooled, counts = _render(view)
    assert (counts == 64).all()  # 8 in the first round (not pooled), 8 + 16 + 32 pooled
    inside, outside = own[:, :6], own[:, -6:]  # columns whose every sample lands on (off) the panel
    assert np.all(inside == pytest.approx(L, rel=1e-6)) and np.all(outside == 0.0)
    # the weighted mean is exact where every sample agrees
    assert np.all(pooled[:, :6] == pytest.approx(L, rel=1e-6)) and np.all(pooled[:, -6:] == 0.0)
    edge_columns = [c for c in range(24) if 0.0 < own[:, c].mean() < L * (1 - 1e-6)]
    assert len(edge_columns) >= 3
    rows = own.shape[0]
    for c in edge_columns:  # each column: one expected value, 96 rows of independent estimates
        sigma = np.sqrt((own[:, c].var() + pooled[:, c].var()) / rows)
        assert abs(pooled[:, c].mean() - own[:, c].mean()) < 4 * sigma + 2e-3 * L
    _, again, _ = _render(PathTraceView(scene, settings, variant=variant))
    assert np.array_equal(np.nan_to_num(again), np.nan_to_num(pooled))  # fixed-point sums: the same bytes


def test_pooled_estimate_lowers_the_noise_of_lit_edges() -> None:
    """A cube on a floor lit by a sun and a dim sky, two bounces: across seeds, the edge pixels' pooled values keep
    the mean of their own samples and vary less in the sRGB values the colors are written as (0.78 times the
    variance; 0.94 in linear light, which its few bright pixels dominate)."""
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.guide_edges import edge_strength

    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    scene = edge_blend_scene()  # the producer test's scene: a cube on a floor, a sun, a dim sky
    pose = scene.camera.keypoints[0]
    guides = DenoiseGuides(scene)
    try:
        edges = edge_strength(*guides.render(pose)) > 1.0
    finally:
        guides.release()
    settings = PathTraceSettings(samples=64, noise_threshold=0.01, min_samples=8, edge_min_samples=64, max_bounces=2)
    view = PathTraceView(scene, settings, variant=variant)
    pool = view.pooled_edges()
    own, pooled = [], []
    for seed in range(6):
        linear, _ = view.render_with_counts(pose, seed=seed, edges=lambda: edges, pool=pool)
        own.append(linear[edges])
        pooled.append(pool.image()[edges])
    own_a, pooled_a = np.array(own, dtype=np.float64), np.array(pooled, dtype=np.float64)
    assert edges.sum() > 100 and np.isfinite(pooled_a).all()
    assert pooled_a.mean() == pytest.approx(own_a.mean(), rel=0.01)
    encoded_own, encoded_pooled = srgb_encode(np.clip(own_a, 0, None)), srgb_encode(np.clip(pooled_a, 0, None))
    assert encoded_pooled.var(axis=0).mean() < 0.85 * encoded_own.var(axis=0).mean()
