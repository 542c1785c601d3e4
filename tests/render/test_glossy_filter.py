"""Filter glossy (Cycles' blur_glossy, render/pathtrace/glossy_filter.py): glossy lobes roughened after rough bounces."""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace import glossy_filter
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def test_roughness_floor_is_cycles_blur(jit_variant):
    import mitsuba as mi

    mi.set_variant(jit_variant)
    pdf = mi.Float([math.inf, 10.0, 1.0, 1 / math.pi, 0.0])
    floor = np.array(glossy_filter.roughness_floor(1.0, pdf))
    alpha = [0.0, 0.0, 0.0, math.sqrt(1 - 1 / math.pi) / 2, 0.5]  # Cycles: sqrt(1 - blur_pdf) / 2 when < 1
    np.testing.assert_allclose(floor ** 2, alpha, atol=1e-6)  # principled alpha = roughness^2
    # Cycles keeps 1 / blur_glossy as its kernel's filter_glossy: a larger blur_glossy blurs more, a smaller less
    after_diffuse = mi.Float([1 / math.pi])  # a cosine-sampled direction straight up
    assert np.array(glossy_filter.roughness_floor(2.0, after_diffuse))[0] ** 2 == pytest.approx(
        math.sqrt(1 - 1 / (2 * math.pi)) / 2, rel=1e-5)
    assert np.array(glossy_filter.roughness_floor(0.5, after_diffuse))[0] ** 2 == pytest.approx(
        math.sqrt(1 - 2 / math.pi) / 2, rel=1e-5)
    assert np.array(glossy_filter.roughness_floor(0.1, after_diffuse))[0] == 0.0  # blur_pdf 10 / pi >= 1: sharp


def _glossy_scene() -> hg.Scene:
    """A lamp over a Lambertian floor with a near-mirror metal wall beside it (caustics on the floor) and a
    glossy plastic tile seen directly."""
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 50.0, name="floor", category_id=1, color=(0.6, 0.6, 0.6))
    floor.material.specular = 0.0
    scene.add(floor)
    mirror = hg.make_primitive("plane", 2.0, name="mirror", category_id=2, color=(0.95, 0.95, 0.95),
                               local2world=hg.object_pose([0.8, 0, 1.0], [0, math.pi / 2, 0]))
    mirror.material.metallic, mirror.material.roughness = 1.0, 0.05
    scene.add(mirror)
    tile = hg.make_primitive("plane", 0.6, name="tile", category_id=3, color=(0.2, 0.3, 0.8),
                             local2world=hg.object_pose([-0.3, 0.0, 0.01]))
    tile.material.roughness, tile.material.specular = 0.1, 0.5
    scene.add(tile)
    scene.world.strength = 0.0
    scene.lights.append(hg.Light("lamp", "POINT", energy=2000.0, local2world=hg.object_pose([0, 0, 2.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.add_keypoint(hg.look_at([-1.5, -0.3, 1.2], [0.3, 0.0, 0.2]))
    return scene


def test_direct_light_and_camera_seen_highlights_are_never_blurred(jit_variant):
    """Camera vertices have no rough bounce before them: with direct light only, filter glossy changes no
    pixel (same samples; equal up to float rounding of the two kernels) - the glossy tile's highlight stays
    sharp."""
    scene = _glossy_scene()
    pose = scene.camera.keypoints[0]
    on = PathTraceView(scene, PathTraceSettings(samples=16, max_bounces=0, filter_glossy=1.0), variant=jit_variant)
    off = PathTraceView(scene, PathTraceSettings(samples=16, max_bounces=0, filter_glossy=0.0), variant=jit_variant)
    assert on.own_integrator
    a, b = on.render(pose, seed=1), off.render(pose, seed=1)
    assert a.max() > 1.0  # something is lit
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-7)


def test_filter_glossy_tames_caustic_fireflies(jit_variant):
    """The floor next to the near-mirror receives the lamp's caustic through floor -> mirror -> lamp paths,
    which a diffuse sample finds rarely and brightly: the floor's mean over a few seeds scatters widely
    without the filter and little with it (unclamped, so only the filter acts)."""
    scene = _glossy_scene()
    pose = scene.camera.keypoints[0]
    ids = hg.RasterView(scene).render(pose, ["instance_segmaps"])["instance_segmaps"]
    floor = ids == 1
    assert floor.sum() > 50

    def spread(filter_glossy: float) -> float:
        view = PathTraceView(scene, PathTraceSettings(samples=32, clamp_indirect=0.0, filter_glossy=filter_glossy),
                             variant=jit_variant)
        means = [view.render(pose, seed=seed)[floor].mean() for seed in range(4)]
        return float(np.std(means) / np.mean(means))

    assert spread(1.0) < 0.3 * spread(0.0)
