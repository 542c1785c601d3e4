"""hybridgen's shuffled, Owen-scrambled Sobol sampler (hybridgen/render/pathtrace/owen_sobol.py, the default of the Python
integrators): every power-of-two prefix of a pattern is stratified, dimension sets are uncorrelated across patterns
(Mitsuba's ldsampler is not: the bias it caused), and a render keeps the expectation of independent random numbers
and is deterministic."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace import adaptive_sampling, owen_sobol, path_trace
from hybridgen.render.pathtrace.mitsuba_variant import activate, choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def _jit_variant() -> str:
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    activate(variant)
    return variant


def _is_net(x: np.ndarray, y: np.ndarray) -> bool:
    """Whether 2^m points are a (0, m, 2)-net: one point in every elementary interval of area 2^-m."""
    m = len(x).bit_length() - 1
    for a in range(m + 1):
        cells = (np.floor(x * 2 ** a).astype(np.int64) << (m - a)) | np.floor(y * 2 ** (m - a)).astype(np.int64)
        if len(np.unique(cells)) != len(x):
            return False
    return True


def test_every_power_of_two_prefix_and_both_halves_are_nets():
    _jit_variant()
    import mitsuba as mi

    n = 256
    for seed in (1, 77, 2 ** 31 + 5):
        sampler = owen_sobol.OwenSobol(mi.UInt32(np.arange(n, dtype=np.uint32)), mi.UInt32(np.full(n, seed, np.uint32)))
        for _ in range(3):  # three dimension sets, each its own shuffle and scramble
            point = sampler.next_2d()
            x, y = np.asarray(point.x, np.float64), np.asarray(point.y, np.float64)
            assert np.all((x >= 0) & (x < 1) & (y >= 0) & (y < 1))
            for size in (4, 16, 64, 256):
                assert _is_net(x[:size], y[:size]), (seed, size)
            assert _is_net(x[n // 2:], y[n // 2:])  # adaptive sampling's second half
    # not a plain copy of Sobol's points: the scramble moves them
    first = owen_sobol.sample_2d(mi.UInt32(np.zeros(2, np.uint32)), mi.UInt32(np.array([1, 2], np.uint32)))
    assert np.asarray(first[0])[0] != np.asarray(first[0])[1]


def _largest_cross_correlation(dims: np.ndarray, samples_per_pattern: int) -> float:
    """Largest |z| of the mean product of two centred dimensions over patterns (rows of ``dims``: dimensions)."""
    centred = dims - 0.5
    patterns = centred.shape[1] // samples_per_pattern
    products = (centred[:, None] * centred[None]).reshape(len(dims) ** 2, patterns, samples_per_pattern).mean(axis=2)
    z = (products.mean(axis=1) / (products.std(axis=1) / np.sqrt(patterns))).reshape(len(dims), len(dims))
    np.fill_diagonal(z, 0.0)
    return float(np.abs(z).max())


def test_dimension_sets_are_uncorrelated_unlike_mitsubas_ldsampler():
    _jit_variant()
    import mitsuba as mi

    n, patterns = 16, 65536
    sobol = owen_sobol.OwenSobol(mi.UInt32(np.tile(np.arange(n, dtype=np.uint32), patterns)),
                                 owen_sobol.mix(mi.UInt32(np.repeat(np.arange(patterns, dtype=np.uint32), n))))
    ld = mi.load_dict({"type": "ldsampler", "sample_count": n})
    ld.set_samples_per_wavefront(n)
    ld.seed(7, n * patterns)
    dims = {"sobol": [], "ld": []}
    for _ in range(4):
        for name, sampler in (("sobol", sobol), ("ld", ld)):
            point = sampler.next_2d()
            dims[name] += [np.asarray(point.x, np.float64), np.asarray(point.y, np.float64)]
    # 28 pairs of 8 dimensions; |z| > 5 by chance has probability ~1e-5 (seeds are fixed: the outcome is too)
    assert _largest_cross_correlation(np.array(dims["sobol"]), n) < 5.0
    assert _largest_cross_correlation(np.array(dims["ld"]), n) > 20.0  # the correlation this sampler replaces


def test_render_keeps_the_expectation_and_is_deterministic(monkeypatch):
    variant = _jit_variant()
    from tests.render.test_world_guide import _box

    scene = _box()
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.4, 48, 36, clip_start=0.01)
    pose = scene.camera.keypoints[0]
    monkeypatch.setattr(path_trace, "SAMPLER", "independent")  # another sensor sampler is kept
    independent = PathTraceView(scene, PathTraceSettings(samples=256), variant=variant)
    assert not independent._tracer.owen_sobol
    expected = np.mean([independent.render(pose, seed=s).mean(axis=(0, 1)) for s in (1, 2)], axis=0)
    monkeypatch.setattr(path_trace, "SAMPLER", "ldsampler")
    view = PathTraceView(scene, PathTraceSettings(samples=256), variant=variant)
    assert view._tracer.owen_sobol
    first, again = view.render(pose, seed=1), view.render(pose, seed=1)
    assert np.array_equal(first, again)
    second = view.render(pose, seed=2)
    assert not np.array_equal(first, second)
    np.testing.assert_allclose(np.mean([first.mean(axis=(0, 1)), second.mean(axis=(0, 1))], axis=0), expected,
                               rtol=0.01)
    # adaptive rounds of any size (80: not a power of two) trace one pattern per pixel and stay deterministic
    adaptive = PathTraceView(scene, PathTraceSettings(min_samples=80), variant=variant)
    image, counts = adaptive.render_with_counts(pose, seed=3)
    assert counts.min() >= 80 and np.array_equal(image, adaptive.render_with_counts(pose, seed=3)[0])


def test_adaptive_rounds_continue_each_pixels_pattern():
    """Samples 0..n-1 of a pixel traced in two rounds (first 0 and n/2) are the samples of one n-sample trace."""
    variant = _jit_variant()
    from tests.render.test_world_guide import _box

    scene = _box()
    view = PathTraceView(scene, PathTraceSettings(samples=64), variant=variant)
    view.set_pose(scene.camera.keypoints[0])
    tracer = view._tracer
    pixels = np.arange(0, tracer.width * tracer.height, 7)
    whole = np.add(*tracer.trace(pixels, 64, seed=5))
    first = np.add(*tracer.trace(pixels, 32, seed=5, first=np.zeros(len(pixels), np.uint32)))
    rest = np.add(*tracer.trace(pixels, 32, seed=5, first=np.full(len(pixels), 32, np.uint32)))
    np.testing.assert_allclose(first + rest, whole, rtol=1e-5, atol=1e-6)
    other = np.add(*tracer.trace(pixels, 32, seed=5, first=np.full(len(pixels), 64, np.uint32)))
    assert not np.allclose(other, rest)  # later samples of the sequence are other samples
    # a sequence past one pattern's MAX_SAMPLES samples goes on in a pattern of its own
    import mitsuba as mi

    beyond = owen_sobol.sample_2d(mi.UInt32([3, owen_sobol.MAX_SAMPLES + 3]), mi.UInt32([9, 9]))
    assert np.asarray(beyond[0])[0] != np.asarray(beyond[0])[1]


def test_every_jit_render_draws_owen_sobol_samples_also_without_clamp_and_filter_glossy():
    """With clamp and filter glossy off the JIT path still runs hybridgen's integrator (Mitsuba's own ``path``
    would draw from the biased ldsampler)."""
    variant = _jit_variant()
    from hybridgen.render.pathtrace import clamped_path
    from tests.render.test_world_guide import _box

    settings = PathTraceSettings(samples=4, clamp_indirect=0.0, filter_glossy=0.0)
    assert settings.integrator_for(variant)["type"] == clamped_path.PLUGIN_NAME
    view = PathTraceView(_box(), settings, variant=variant)
    assert view.own_integrator and not view.clamped and view._tracer.owen_sobol
    assert settings.integrator_for("scalar_rgb")["type"] == "path"
