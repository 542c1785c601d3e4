"""Raw samples mixed back into denoised colors on strong guide edges (hybridgen.render.edge_blend): the arithmetic on
its own, then the color producer's output - with the whole raw share, strong-edge pixels carry the raw colors and
every other pixel the denoised ones, whichever way the guides are made."""
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
def test_the_producer_keeps_the_raw_colors_on_strong_edges(gl_context, shared_raster: bool) -> None:
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.raster.scene_raster import SceneRaster
    from hybridgen.render.render_color import ColorProducer

    scene = _scene()
    pose = scene.camera.keypoints[0]
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
        strong = edge_strength(*guides.render(pose)) >= STRONG_EDGE
    finally:
        guides.release()
    assert 20 < strong.sum() < strong.size / 3
    mixed, plain = outputs[1.0], outputs[0.0]
    assert np.array_equal(mixed["colors_raw"], plain["colors_raw"])  # the same samples
    assert np.array_equal(mixed["colors"][strong], mixed["colors_raw"][strong])
    assert np.array_equal(mixed["colors"][~strong], plain["colors"][~strong])
    assert not np.array_equal(plain["colors"][strong], plain["colors_raw"][strong])  # the denoiser did change them
