"""Sampler distributions against their definitions, validation at load time, selection."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import ConfigError
from hybridgen.sampling.getters import parse_selector
from hybridgen.sampling.registry import DrawContext, draw, parse_value

N = 4000


def _draws(spec: dict, n: int = N, scene=None, seed: int = 0) -> np.ndarray:
    value = parse_value(spec, "x")
    ctx = DrawContext(np.random.default_rng(seed), scene)
    return np.array([draw(value, ctx) for _ in range(n)])


def test_sphere_surface_and_interior():
    centre = np.array([1.0, -2.0, 0.5])
    surface = _draws({"name": "SphereSampler", "parameters": {"center": centre.tolist(), "radius": 2.0,
                                                              "mode": "SURFACE"}})
    np.testing.assert_allclose(np.linalg.norm(surface - centre, axis=1), 2.0, rtol=1e-12)
    assert np.abs((surface - centre).mean(axis=0)).max() < 0.1  # isotropic
    interior = _draws({"provider": "sampler.Sphere", "center": centre.tolist(), "radius": 2.0, "mode": "INTERIOR"})
    r = np.linalg.norm(interior - centre, axis=1)
    assert r.max() <= 2.0
    # uniform in volume: P(r < R/2) = 1/8
    assert abs((r < 1.0).mean() - 0.125) < 0.02


def test_shell_bounds_and_uniform_directions():
    pts = _draws({"provider": "sampler.Shell", "center": [0, 0, 0], "radius_min": 1.0, "radius_max": 3.0,
                  "elevation_min": 20, "elevation_max": 60, "azimuth_min": -90, "azimuth_max": 90})
    r = np.linalg.norm(pts, axis=1)
    elevation = np.degrees(np.arcsin(pts[:, 2] / r))
    azimuth = np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
    assert r.min() >= 1.0 and r.max() <= 3.0
    assert elevation.min() >= 20 - 1e-9 and elevation.max() <= 60 + 1e-9
    assert azimuth.min() >= -90 and azimuth.max() <= 90
    # uniform on the band: sin(elevation) is uniform
    s = np.sin(np.radians(elevation))
    assert abs(s.mean() - (np.sin(np.radians(20)) + np.sin(np.radians(60))) / 2) < 0.01


def test_uniform_box_and_disk_variants():
    box = _draws({"provider": "sampler.Uniform3d", "min": [0, -1, 2], "max": [1, 1, 2]})
    assert (box >= [0, -1, 2]).all() and (box <= [1, 1, 2]).all()
    assert abs(box[:, 0].mean() - 0.5) < 0.02
    disk = _draws({"provider": "sampler.Disk", "center": [0, 0, 1], "radius": 2.0})
    rr = np.linalg.norm(disk[:, :2], axis=1)
    assert rr.max() <= 2.0 and abs((rr < 1.0).mean() - 0.25) < 0.03 and np.allclose(disk[:, 2], 1)
    circle = _draws({"provider": "sampler.Disk", "center": [0, 0, 0], "radius": 2.0, "sample_from": "circle"})
    np.testing.assert_allclose(np.linalg.norm(circle, axis=1), 2.0)
    sector = _draws({"provider": "sampler.Disk", "center": [0, 0, 0], "radius": 1.0, "sample_from": "sector",
                     "start_angle": 0, "end_angle": 90})
    assert (sector[:, 0] >= -1e-12).all() and (sector[:, 1] >= -1e-12).all()


def test_part_sphere_stays_above_the_cut():
    pts = _draws({"provider": "sampler.PartSphere", "center": [0, 0, 0], "radius": 1.0,
                  "distance_above_center": 0.5, "part_sphere_dir_vector": [0, 0, 1]}, n=500)
    assert (pts[:, 2] > 0.5).all()
    np.testing.assert_allclose(np.linalg.norm(pts, axis=1), 1.0)


def test_uniform_so3_is_uniform():
    from scipy.spatial.transform import Rotation

    angles = _draws({"provider": "sampler.UniformSO3"})
    rotations = Rotation.from_euler("xyz", angles)
    # for a uniform rotation the rotated z axis is uniform on the sphere: mean ~ 0, E[z^2] = 1/3
    axes = rotations.apply([0, 0, 1])
    assert np.abs(axes.mean(axis=0)).max() < 0.05
    assert abs((axes[:, 2] ** 2).mean() - 1 / 3) < 0.02
    # and the rotation angle has density (1 - cos t) / pi: E[cos t] = -1/2... mean trace = 0
    traces = np.trace(rotations.as_matrix(), axis1=1, axis2=2)
    assert abs(traces.mean()) < 0.08
    z_only = _draws({"provider": "sampler.UniformSO3", "around_x": False, "around_y": False}, n=200)
    assert (z_only[:, :2] == 0).all() and z_only[:, 2].std() > 1.0


def test_value_color_path(tmp_path):
    ints = _draws({"provider": "sampler.Value", "type": "int", "min": 2, "max": 4})
    assert set(ints.tolist()) == {2, 3, 4}
    normal = _draws({"provider": "sampler.Value", "mode": "normal", "mean": 3.0, "std_dev": 0.5})
    assert abs(normal.mean() - 3.0) < 0.03 and abs(normal.std() - 0.5) < 0.03
    standard = _draws({"provider": "sampler.Value", "mode": "normal"})  # defaults: mean 0, std_dev 1
    assert abs(standard.mean()) < 0.06 and abs(standard.std() - 1.0) < 0.05
    colors = _draws({"provider": "sampler.Color", "min": [0, 0.5, 0, 1], "max": [0.2, 0.5, 1, 1]}, n=200)
    assert (colors[:, 1] == 0.5).all() and colors[:, 0].max() <= 0.2
    for name in ("b.png", "a.png", "c.txt"):
        (tmp_path / name).write_text("x")
    picks = _draws({"provider": "sampler.Path", "path": str(tmp_path / "*.png")}, n=100)
    assert set(picks) == {str(tmp_path / "a.png"), str(tmp_path / "b.png")}


def test_same_seed_same_draws():
    spec = {"provider": "sampler.Shell", "center": [0, 0, 0], "radius_min": 1, "radius_max": 2}
    np.testing.assert_array_equal(_draws(spec, 50, seed=4), _draws(spec, 50, seed=4))
    assert not np.array_equal(_draws(spec, 50, seed=4), _draws(spec, 50, seed=5))


@pytest.mark.parametrize("spec,fragment", [
    ({"provider": "sampler.Uniform3d", "min": [1, 0, 0], "max": [0, 1, 1]}, "min"),
    ({"provider": "sampler.Shell", "center": [0, 0, 0], "radius_min": 3, "radius_max": 1}, "min"),
    ({"provider": "sampler.Shell", "center": [0, 0, 0], "radius_min": 1, "radius_max": 2, "elevation_max": 120},
     "elevation_max"),
    ({"provider": "sampler.Sphere", "center": [0, 0, 0], "radius": -1}, "radius"),
    ({"provider": "sampler.Value", "min": 2, "max": 1}, "min"),
    ({"provider": "sampler.Uniform3d", "min": [0, 0, 0]}, "needs max"),
    ({"provider": "sampler.Uniform3d", "min": [0, 0, 0], "max": [1, 1, 1], "mx": 1}, "no parameter 'mx'"),
    ({"name": "Uniform3dSamplr", "parameters": {}}, "did you mean 'Uniform3dSampler'"),
])
def test_bad_sampler_specs_fail_at_load(spec, fragment):
    with pytest.raises(ConfigError) as info:
        parse_value(spec, "location")
    assert fragment in str(info.value) and "location" in str(info.value)


def _scene() -> hg.Scene:
    scene = hg.Scene()
    for i, (name, cat, color) in enumerate([("chair.001", 1, "red"), ("chair.002", 1, "blue"),
                                            ("table", 2, "red"), ("lamp", 3, "white")]):
        scene.add(hg.make_primitive("cube", 1.0, name=name, category_id=cat, attributes={"color": color},
                                    local2world=hg.object_pose([3.0 * i, 0, 0.5])))
    return scene


def test_selectors():
    scene = _scene()
    names = lambda sel: [o.name for o in parse_selector(sel).select(scene.objects, np.random.default_rng(0))]  # noqa: E731
    assert names({"name": "chair.*"}) == ["chair.001", "chair.002"]
    assert names({"name": "chair.*", "color": "red"}) == ["chair.001"]  # AND
    assert names({"conditions": [{"category_id": 2}, {"cp_color": "white"}]}) == ["table", "lamp"]  # OR
    assert names({"provider": "getter.Entity", "conditions": {"category_id": 1}, "random_samples": 1})[0] in \
        ("chair.001", "chair.002")
    assert names(None) == ["chair.001", "chair.002", "table", "lamp"]
    with pytest.raises(ConfigError, match="regular expression"):
        parse_selector({"name": "chair(["})


def test_poi_and_upper_region():
    scene = _scene()
    poi = _draws({"provider": "getter.POI", "selector": {"conditions": {"category_id": 1}}}, n=1, scene=scene)[0]
    np.testing.assert_allclose(poi, [0.0, 0, 0.5])  # of centres (0,0,.5) and (3,0,.5), mean (1.5,..): tie -> first
    pts = _draws({"provider": "sampler.UpperRegionSampler", "to_sample_on": {"name": "table"},
                  "min_height": 0.2, "max_height": 0.4}, n=300, scene=scene)
    assert (pts[:, 2] >= 1.2).all() and (pts[:, 2] <= 1.4).all()
    assert (pts[:, 0] >= 5.5).all() and (pts[:, 0] <= 6.5).all() and (np.abs(pts[:, 1]) <= 0.5).all()
