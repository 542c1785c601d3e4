"""Per-dimension Cranley-Patterson rotations of the low-discrepancy sampler (adaptive_sampling.RotatedDimensions,
off by default): each dimension of a sequence is shifted by its own hash, values stay in [0, 1), and a render
with rotations keeps the expectation of independent random numbers."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.render import adaptive_sampling, path_trace
from hybridgen.render.adaptive_sampling import RotatedDimensions
from hybridgen.render.mitsuba_variant import activate, choose_variant
from hybridgen.render.path_trace import PathTraceSettings, PathTraceView


def _jit_variant() -> str:
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    return variant


class _Fixed:
    """A stand-in sampler that returns the same values in every dimension."""

    def __init__(self, values: np.ndarray) -> None:
        import mitsuba as mi

        self.values = mi.Float(values.astype(np.float32))

    def next_1d(self, active=True):
        return self.values

    def next_2d(self, active=True):
        import mitsuba as mi

        return mi.Point2f(self.values, self.values)


def test_each_dimension_is_shifted_by_its_own_hash_of_the_sequence():
    activate(_jit_variant())
    import mitsuba as mi

    values = np.array([0.0, 0.25, 0.5, 0.999, 0.0, 0.25, 0.5, 0.999])
    sequence = np.array([0, 0, 0, 0, 1, 1, 1, 1], np.uint32)
    rotated = RotatedDimensions(_Fixed(values), mi.UInt32(sequence), mi.UInt32(77))
    first = np.asarray(rotated.next_1d(), np.float64)
    pair = rotated.next_2d()
    out = [first, np.asarray(pair.x, np.float64), np.asarray(pair.y, np.float64)]
    for dimension, got in enumerate(out, start=1):
        shift = np.asarray(mi.sample_tea_float32(mi.UInt32(sequence), mi.UInt32(77 + dimension * 0x9E3779B9 % 2**32),
                                                 6), np.float64)
        np.testing.assert_allclose(got, np.minimum((values + shift) % 1.0, 0.99999994), atol=1e-6)
        assert np.all((got >= 0) & (got < 1))
    assert len({round(float(o[0]), 6) for o in out}) == 3  # three dimensions, three shifts
    assert out[0][0] != pytest.approx(out[0][4])  # two sequences, two shifts


def test_rotated_render_keeps_the_expectation_and_is_deterministic(monkeypatch):
    variant = _jit_variant()
    from tests.render.test_world_guide import _box

    scene = _box()
    pose = scene.camera.keypoints[0]
    monkeypatch.setattr(path_trace, "SAMPLER", "independent")
    independent = PathTraceView(scene, PathTraceSettings(samples=256), variant=variant)
    expected = np.mean([independent.render(pose, seed=s).mean(axis=(0, 1)) for s in (1, 2)], axis=0)
    monkeypatch.setattr(path_trace, "SAMPLER", "ldsampler")
    monkeypatch.setattr(adaptive_sampling, "ROTATE_DIMENSIONS", True)
    view = PathTraceView(scene, PathTraceSettings(samples=256), variant=variant)
    first, again = view.render(pose, seed=1), view.render(pose, seed=1)
    assert np.array_equal(first, again)
    rotated = np.mean([first.mean(axis=(0, 1)), view.render(pose, seed=2).mean(axis=(0, 1))], axis=0)
    np.testing.assert_allclose(rotated, expected, rtol=0.01)
    monkeypatch.setattr(adaptive_sampling, "ROTATE_DIMENSIONS", False)
    assert not np.array_equal(view.render(pose, seed=1), first)  # the switch changes the samples
