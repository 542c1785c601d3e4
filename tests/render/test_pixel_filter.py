"""The pixel filter of the path-traced color (Cycles' Blackman-Harris, importance-sampled)."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render import pixel_filter
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def test_blackman_harris_window_has_cycles_support_and_shape():
    # Cycles evaluates filter_width w over [-w, w]: 1 at the centre, ~0 (6e-5) at the ends, 0 beyond
    assert pixel_filter.blackman_harris(np.array([0.0]), 1.5)[0] == pytest.approx(1.0)
    ends = pixel_filter.blackman_harris(np.array([-1.5, 1.5]), 1.5)
    np.testing.assert_allclose(ends, 0.35875 - 0.48829 + 0.14128 - 0.01168, atol=1e-12)
    assert pixel_filter.blackman_harris(np.array([1.6, -2.0]), 1.5).tolist() == [0.0, 0.0]
    x = np.linspace(0.0, 1.5, 50)
    np.testing.assert_allclose(pixel_filter.blackman_harris(x, 1.5), pixel_filter.blackman_harris(-x, 1.5))


def test_sample_warp_draws_offsets_with_the_filters_density():
    table = pixel_filter.inverse_cdf_table(1.5)
    assert table[0] == -1.5 and table[-1] == 1.5 and abs(table[len(table) // 2]) < 1e-12
    offsets = pixel_filter.warp(table, (np.arange(200_000) + 0.5) / 200_000)
    counts, edges = np.histogram(offsets, bins=30, range=(-1.5, 1.5))
    centres = (edges[1:] + edges[:-1]) / 2
    density = pixel_filter.blackman_harris(centres, 1.5)
    np.testing.assert_allclose(counts / counts.sum(), density / density.sum(), atol=2e-3)
    # the one-pixel box: uniform offsets over the pixel
    box = pixel_filter.warp(pixel_filter.inverse_cdf_table(0.0), np.array([0.0, 0.25, 0.5, 1.0]))
    np.testing.assert_allclose(box, [-0.5, -0.25, 0.0, 0.5])


def test_supersampled_filter_conserves_energy_and_reduces_to_the_box():
    rng = np.random.default_rng(3)
    fine = rng.random((12 * 3, 16 * 3, 2)).astype(np.float32)
    box = fine.reshape(12, 3, 16, 3, 2).mean(axis=(1, 3))
    np.testing.assert_allclose(pixel_filter.filter_supersampled(fine, 3, 0.0), box, atol=1e-6)
    # weights sum to one: a constant image keeps its value; symmetric: a linear ramp keeps the centre value
    constant = pixel_filter.filter_supersampled(np.full((30, 24, 1), 0.37, np.float32), 3, 1.5)
    np.testing.assert_allclose(constant, 0.37, rtol=1e-6)
    u = (np.arange(24 * 3) + 0.5) / 3  # fine sub-pixel centres in pixel units
    ramp = np.broadcast_to(u[None, :, None], (30, 72, 1)).astype(np.float32)
    filtered = pixel_filter.filter_supersampled(ramp, 3, 1.5)[:, 2:-2, 0]
    np.testing.assert_allclose(filtered, np.broadcast_to(np.arange(2, 22) + 0.5, filtered.shape), atol=1e-5)
    weights = pixel_filter.pixel_weights(1.5, np.arange(-4, 5) / 3)
    assert weights.sum() == pytest.approx(1.0) and np.allclose(weights, weights[::-1])


def test_supersampled_filter_is_the_weighted_sum_around_each_pixel():
    # more output rows than one block of the summation (pixel_filter.ROW_BLOCK): every block and its edges
    rng = np.random.default_rng(5)
    f, rows, cols = 3, pixel_filter.ROW_BLOCK * 2 + 5, 7
    fine = rng.random((rows * f, cols * f, 2)).astype(np.float32)
    reach = int(np.ceil(1.5 * f))
    taps = np.arange(-reach, reach + f)
    w = pixel_filter.pixel_weights(1.5, (taps + 0.5) / f - 0.5)
    padded = np.pad(fine, ((reach, reach), (reach, reach), (0, 0)), mode="edge").astype(np.float64)
    expected = np.empty((rows, cols, 2))
    for r in range(rows):
        for c in range(cols):
            window = padded[r * f:r * f + len(taps), c * f:c * f + len(taps)]
            expected[r, c] = np.einsum("i,j,ijk->k", w, w, window)
    np.testing.assert_allclose(pixel_filter.filter_supersampled(fine, f, 1.5), expected, rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("filter_width", [1.5, 0.0])
def test_rendered_edge_follows_the_filters_cumulative_profile(filter_width):
    """Looking straight down at an emitting half-plane x < 0 (radiance 1, black elsewhere) whose edge runs
    between pixel centres: pixel u's value is the probability that one of its samples lands on the emitter,
    the filter's CDF at the edge's offset from the pixel centre - 0.5 at the edge, symmetric, and nonzero up
    to filter_width px away (one pixel for the box)."""
    variant = choose_variant()
    if not is_jit(variant):
        pytest.skip("the pixel filter is sampled by the JIT variants' pixel tracer")
    width, height, f, camera_height = 16, 6, 20.0, 2.0
    cx = 7.3  # the edge (world x = 0) crosses the image at u = 7.3
    scene = hg.Scene()
    panel = hg.make_primitive("plane", 10.0, name="panel", category_id=1, color=(0.0, 0.0, 0.0),
                              local2world=hg.object_pose([-5.0, 0, 0]))
    panel.material.emission, panel.material.emission_strength, panel.material.specular = (1.0, 1.0, 1.0), 1.0, 0.0
    scene.add(panel)
    scene.world.strength = 0.0
    scene.camera.intrinsics = hg.Intrinsics(np.array([[f, 0, cx], [0, f, 2.5], [0, 0, 1]]), width, height)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, camera_height], [0, 0, 0, 1]]))
    settings = PathTraceSettings(samples=1024, max_bounces=0, filter_width=filter_width)
    image = PathTraceView(scene, settings, variant=variant).render(scene.camera.keypoints[0], seed=3)
    table = pixel_filter.inverse_cdf_table(filter_width)
    cdf_x = np.linspace(0.0, 1.0, len(table))
    expected = np.interp(cx - np.arange(width), table, cdf_x)  # P(offset < edge - centre)
    row = image[2:4, :, 0].mean(axis=0)
    np.testing.assert_allclose(row, expected, atol=0.01)
    reach = max(filter_width, 0.5)
    assert (row[np.arange(width) < cx - reach - 1e-3] == 1.0).all()
    assert (row[np.arange(width) > cx + reach + 1e-3] == 0.0).all()
