"""Raw samples mixed back into denoised colors on guide edges (hybridgen.render.edge_blend): the arithmetic on its own
(the raw samples on strong edges, or the pooled estimate where there is one), then the color producer's output - with
the whole raw share, edge pixels carry the pooled estimate (hybridgen.render.pathtrace.pooled_edges) and every other
pixel the denoised colors, whichever way the guides are made."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.edge_blend import STRONG_EDGE, mix_raw_on_edges
from hybridgen.render.guide_edges import edge_strength
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant


def test_the_mix_is_weighted_on_strong_edges_only() -> None:
    rng = np.random.default_rng(3)
    denoised = rng.random((4, 5, 3), dtype=np.float32)
    raw = rng.random((4, 5, 3), dtype=np.float32)
    strength = np.zeros((4, 5), np.float32)
    strength[1, 2] = STRONG_EDGE
    strength[2, 3] = STRONG_EDGE * 10
    strength[0, 0] = STRONG_EDGE - 1e-3  # just below: untouched
    before = denoised.copy()
    out = mix_raw_on_edges(denoised, raw, strength, 0.25)
    strong = strength >= STRONG_EDGE
    np.testing.assert_allclose(out[strong], 0.25 * raw[strong] + 0.75 * denoised[strong], rtol=1e-6)
    assert np.array_equal(out[~strong], denoised[~strong])
    assert out.dtype == np.float32
    assert np.array_equal(denoised, before)  # the input is kept
    assert mix_raw_on_edges(denoised, raw, strength, 0.0) is denoised
    assert np.array_equal(mix_raw_on_edges(denoised, raw, strength, 1.0)[strong], raw[strong])


def test_edge_raw_weight_is_checked() -> None:
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(hg.InputError, match="edge_raw_weight"):
            hg.PathTraceSettings(edge_raw_weight=bad)


def _scene() -> hg.Scene:
    """A white cube on a grey floor, lit by a sun (silhouettes, a crease, a shadow edge)."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=1, color=(0.9, 0.9, 0.9)))
    floor = hg.make_primitive("plane", 6.0, name="floor", category_id=2, color=(0.2, 0.3, 0.5))
    floor.local2world = hg.object_pose([0, 0, -0.5], [0, 0, 0])
    scene.add(floor)
    scene.world.strength = 0.3
    scene.lights.append(hg.Light("sun", "SUN", energy=3.0, local2world=hg.object_pose([0, 0, 3], [0.4, 0.3, 0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 40, 30)
    scene.camera.add_keypoint(hg.look_at([2.2, -2.6, 1.8], [0, 0, 0]))
    return scene


@pytest.mark.parametrize("shared_raster", [False, True])
def test_the_producer_mixes_the_pooled_estimate_on_edges(gl_context, monkeypatch, shared_raster: bool) -> None:
    from hybridgen.render import render_color
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.raster.scene_raster import SceneRaster
    from hybridgen.render.render_color import ColorProducer
    from hybridgen.render.tonemap import to_srgb8

    if choose_variant() == "scalar_rgb":
        pytest.skip("pooling needs a JIT Mitsuba variant")
    scene = _scene()
    pose = scene.camera.keypoints[0]
    mixes: list[dict] = []

    def recording(denoised, raw, strength, weight, pooled=None):
        mixes.append({"raw": raw, "pooled": pooled})
        return mix_raw_on_edges(denoised, raw, strength, weight, pooled)

    monkeypatch.setattr(render_color, "mix_raw_on_edges", recording)
    outputs = {}
    for weight in (0.0, 1.0):
        settings = hg.PathTraceSettings(samples=16, noise_threshold=0.01, min_samples=4, edge_min_samples=16,
                                        max_bounces=1, edge_raw_weight=weight)
        raster = SceneRaster(scene) if shared_raster else None
        producer = ColorProducer(scene, settings, variant=choose_variant(), denoise=True, keep_raw=True,
                                 raster=raster)
        try:
            outputs[weight] = producer.produce(0, pose)
        finally:
            producer.close()
            if raster is not None:
                raster.release()
    guides = DenoiseGuides(scene)
    try:
        edges = edge_strength(*guides.render(pose)) > 1.0
    finally:
        guides.release()
    assert 20 < edges.sum() < edges.size / 2
    assert len(mixes) == 1  # weight 0: no mix at all
    pooled, raw = mixes[0]["pooled"], mixes[0]["raw"]
    assert np.array_equal(np.isfinite(pooled).all(axis=2), edges)  # pooled exactly on the edge pixels
    mixed, plain = outputs[1.0], outputs[0.0]
    assert np.array_equal(mixed["colors_raw"], plain["colors_raw"])  # the same samples
    assert np.array_equal(mixed["colors"][edges], to_srgb8(pooled)[edges])
    assert np.array_equal(mixed["colors"][~edges], plain["colors"][~edges])
    assert not np.array_equal(plain["colors"][edges], plain["colors_raw"][edges])  # the denoiser did change them
    # the pooled estimate has the raw samples' expectation: their means over the edge pixels agree closely
    assert abs(pooled[edges].mean() - raw[edges].mean()) < 0.03 * raw[edges].mean()
    assert not np.array_equal(pooled[edges], raw[edges])


def test_without_a_pool_the_raw_samples_are_mixed_on_strong_edges() -> None:
    rng = np.random.default_rng(5)
    denoised, raw, pooled = (rng.random((3, 4, 3), dtype=np.float32) for _ in range(3))
    strength = np.zeros((3, 4), np.float32)
    strength[1, 1] = STRONG_EDGE
    strength[2, 2] = 2.0  # an edge, not a strong one
    pooled[:] = np.nan
    pooled[2, 2] = 0.5
    with_pool = mix_raw_on_edges(denoised, raw, strength, 0.5, pooled)
    np.testing.assert_allclose(with_pool[2, 2], 0.5 * 0.5 + 0.5 * denoised[2, 2], rtol=1e-6)
    assert np.array_equal(with_pool[1, 1], denoised[1, 1])  # where the pool has no value: denoised
    without = mix_raw_on_edges(denoised, raw, strength, 0.5)
    np.testing.assert_allclose(without[1, 1], 0.5 * raw[1, 1] + 0.5 * denoised[1, 1], rtol=1e-6)
    assert np.array_equal(without[2, 2], denoised[2, 2])
