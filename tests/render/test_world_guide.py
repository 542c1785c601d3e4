"""Light samples of a constant world seen through openings (hybridgen/render/pathtrace/world_guide.py, off by default).

A 2 x 2 x 2 m box with a 0.8 x 0.8 m hole in one wall, lit by a point lamp inside and a constant sky outside:
with the guide on, the image keeps its expectation (independent random numbers, so only the estimator is
compared) while the noise between two seeds drops; the learned density is a density (integrates to 1) and the
integrator's Dr.Jit density equals the NumPy one; open scenes and the default get no guide.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace import path_trace, world_guide
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def _jit_variant() -> str:
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    return variant


def _wall(name: str, sx: float, sy: float, pose: np.ndarray) -> hg.MeshObject:
    wall = hg.make_primitive("plane", 1.0, name=name, category_id=1, color=(0.7, 0.7, 0.7),
                             local2world=pose @ np.diag([sx, sy, 1.0, 1.0]))
    wall.material.specular = 0.0
    return wall


def _box(hole: bool = True) -> hg.Scene:
    """Floor z = 0, ceiling z = 2, walls at x, y = +-1; the +y wall has a hole x in [-0.4, 0.4], z in [0.6, 1.4]."""
    scene = hg.Scene()
    h = math.pi / 2
    parts = [("floor", 2, 2, hg.object_pose([0, 0, 0])),
             ("ceiling", 2, 2, hg.object_pose([0, 0, 2], [math.pi, 0, 0])),
             ("west", 2, 2, hg.object_pose([-1, 0, 1], [0, h, 0])),
             ("east", 2, 2, hg.object_pose([1, 0, 1], [0, -h, 0])),
             ("south", 2, 2, hg.object_pose([0, -1, 1], [-h, 0, 0]))]
    if hole:
        parts += [("north_left", 0.6, 2, hg.object_pose([-0.7, 1, 1], [h, 0, 0])),
                  ("north_right", 0.6, 2, hg.object_pose([0.7, 1, 1], [h, 0, 0])),
                  ("north_below", 0.8, 0.6, hg.object_pose([0, 1, 0.3], [h, 0, 0])),
                  ("north_above", 0.8, 0.6, hg.object_pose([0, 1, 1.7], [h, 0, 0]))]
    for part in parts:
        scene.add(_wall(*part))
    scene.world.color, scene.world.strength = (0.5, 0.7, 1.0), 3.0
    scene.add_light(hg.Light("lamp", "POINT", energy=5.0, local2world=hg.object_pose([-0.5, -0.5, 1.8])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.4, 24, 18, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.6, -0.8, 0.5], [0.0, 1.0, 1.0]))
    return scene


def _renders(scene: hg.Scene, enabled: bool, monkeypatch: pytest.MonkeyPatch, variant: str) -> tuple[list, object]:
    monkeypatch.setattr(world_guide, "ENABLED", enabled)
    monkeypatch.setattr(path_trace, "SAMPLER", "independent")
    view = PathTraceView(scene, PathTraceSettings(samples=256), variant=variant)
    pose = scene.camera.keypoints[0]
    return [view.render(pose, seed=seed).astype(np.float64) for seed in (1, 2)], view._tracer.world_guide


def test_guide_keeps_the_expectation_and_lowers_the_noise(monkeypatch):
    variant = _jit_variant()
    scene = _box()
    plain, none = _renders(scene, False, monkeypatch, variant)
    guided, guide = _renders(scene, True, monkeypatch, variant)
    assert none is None and guide is not None and guide.open_fraction < world_guide.MAX_OPEN_FRACTION
    plain_mean, guided_mean = np.mean(plain, axis=(0, 1, 2)), np.mean(guided, axis=(0, 1, 2))
    np.testing.assert_allclose(guided_mean, plain_mean, rtol=0.015)
    noise = [np.mean((a - b) ** 2) for a, b in (plain, guided)]
    assert noise[1] < 0.7 * noise[0]


def test_open_scene_and_default_get_no_guide(monkeypatch):
    variant = _jit_variant()
    pose = _box().camera.keypoints[0]
    view = PathTraceView(_box(), PathTraceSettings(samples=4), variant=variant)
    view.render(pose, seed=1)
    assert not world_guide.ENABLED and view._tracer.world_guide is None
    assert view.mi_scene.integrator().world_guide is None
    monkeypatch.setattr(world_guide, "ENABLED", True)
    outdoors = _box()
    outdoors.objects[:] = [obj for obj in outdoors.objects if obj.name in ("floor", "south")]
    open_view = PathTraceView(outdoors, PathTraceSettings(samples=4), variant=variant)
    open_view.render(pose, seed=1)
    assert open_view._tracer.world_guide is None


def test_learned_density_integrates_to_one_and_matches_the_integrators():
    _jit_variant()
    import mitsuba as mi

    rng = np.random.default_rng(3)
    points = rng.uniform(-1, 1, (4000, 3))
    directions = rng.normal(size=(4000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    free = directions[:, 1] > 0.8 - 0.3 * points[:, 0]  # an opening whose direction depends on the place
    guide = world_guide.from_rays(points, directions, free)
    assert guide is not None
    u = rng.normal(size=(200000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    for p in ([0.9, 0.0, 0.0], [-0.9, 0.5, -0.5]):
        at = np.broadcast_to(np.array(p), u.shape)
        assert world_guide.density(guide, at, u).mean() * 4 * math.pi == pytest.approx(1.0, abs=0.02)
    jit = world_guide.JitGuide.of(guide, [1.0, 1.0, 1.0])
    d, pdf = world_guide.sample(jit, mi.Point3f(*points[:1000].T.astype(np.float32)), mi.Float(rng.random(1000)),
                                mi.Point2f(*rng.random((2, 1000))))
    d = np.stack([np.asarray(c, np.float64) for c in d], axis=1)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.asarray(pdf), world_guide.density(guide, points[:1000], d), rtol=1e-4)
