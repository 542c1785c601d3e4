"""bproc.sampler: bounds and distributions, and the same values as BlenderProc 2.8's own samplers (run from
the installed blenderproc package, tests/bproc/bproc_reference.py) under the same seeds."""
from __future__ import annotations

import random
from types import SimpleNamespace
from typing import Any, Callable

import numpy as np
import pytest
from scipy import stats
from scipy.spatial.transform import Rotation

import bproc_reference
from hybridgen.bproc import sampler
from hybridgen.bproc.math import build_transformation_mat


def _same_draws(ours: Callable[[], Any], theirs: Callable[[], Any], seed: int) -> tuple[Any, Any]:
    """Both results from the same seeds of np.random and random, after checking that both consumed the same
    numbers of draws (the next draw of each state agrees)."""
    results, after = [], []
    for call in (ours, theirs):
        np.random.seed(seed)
        random.seed(seed)
        results.append(call())
        after.append((np.random.rand(), random.random()))
    assert after[0] == after[1]
    return results[0], results[1]


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_shape_samplers_draw_what_blenderproc_draws(seed: int) -> None:
    sphere, part, shell, disk = (bproc_reference.sampler(name) for name in ("Sphere", "PartSphere", "Shell", "Disk"))
    cases = [
        (lambda: sampler.sphere([1, 2, 3], 2.0, "SURFACE"), lambda: sphere.sphere([1, 2, 3], 2.0, "SURFACE")),
        (lambda: sampler.sphere([0, 0, 0], 0.5, "INTERIOR"), lambda: sphere.sphere([0, 0, 0], 0.5, "INTERIOR")),
        (lambda: sampler.part_sphere([0, 0, 1], 3, "SURFACE", dist_above_center=2.5, part_sphere_dir_vector=[1, 1, 0]),
         lambda: part.part_sphere([0, 0, 1], 3, "SURFACE", dist_above_center=2.5, part_sphere_dir_vector=[1, 1, 0])),
        (lambda: sampler.shell([0, 0, 0], 1, 4, 10, 80, -45, 90),
         lambda: shell.shell([0, 0, 0], 1, 4, 10, 80, -45, 90)),
        (lambda: sampler.shell([1, 0, 0], 1, 4, 60, 80, 0, 30, uniform_volume=True),
         lambda: shell.shell([1, 0, 0], 1, 4, 60, 80, 0, 30, uniform_volume=True)),
        (lambda: sampler.disk([0, 0, 4], 7, [0.3, 0.2, 0.1]), lambda: disk.disk([0, 0, 4], 7, [0.3, 0.2, 0.1])),
        (lambda: sampler.disk([0, 0, 4], 7, sample_from="circle"),
         lambda: disk.disk([0, 0, 4], 7, sample_from="circle")),
        (lambda: sampler.disk([0, 0, 0], 2, None, "sector", 100, 130),
         lambda: disk.disk([0, 0, 0], 2, None, "sector", 100, 130)),
        (lambda: sampler.disk([0, 0, 0], 2, [0, 1, 0], "arc", -30, 10),
         lambda: disk.disk([0, 0, 0], 2, [0, 1, 0], "arc", -30, 10)),
    ]
    for ours, theirs in cases:
        mine, reference = _same_draws(ours, theirs, seed)
        np.testing.assert_allclose(mine, reference, rtol=1e-12, atol=1e-12)


def test_sphere_and_part_sphere_bounds() -> None:
    np.random.seed(5)
    surface = np.array([sampler.sphere([1, 0, 0], 2.0, "SURFACE") for _ in range(500)]) - [1, 0, 0]
    np.testing.assert_allclose(np.linalg.norm(surface, axis=1), 2.0, rtol=1e-12)
    inside = np.linalg.norm([sampler.sphere([0, 0, 0], 2.0, "INTERIOR") for _ in range(4000)], axis=1)
    assert inside.max() <= 2.0
    assert abs(np.mean((inside / 2.0) ** 3) - 0.5) < 0.02  # uniform by volume: (r/R)^3 is uniform
    cap = np.array([sampler.part_sphere([0, 0, 0], 1.0, "INTERIOR", 0.5, [0, 0, 2]) for _ in range(300)])
    assert cap[:, 2].min() > 0.5 and np.linalg.norm(cap, axis=1).max() <= 1.0
    with pytest.raises(ValueError, match="dist_above_center"):
        sampler.part_sphere([0, 0, 0], 1.0, "SURFACE", 1.0)
    with pytest.raises(ValueError, match="unknown mode"):
        sampler.sphere([0, 0, 0], 1.0, "surface")


@pytest.mark.parametrize("uniform_volume", [False, True])
def test_shell_stays_in_its_band(uniform_volume: bool) -> None:
    np.random.seed(11)
    points = np.array([sampler.shell([0, 0, 1], 2, 3, 15, 60, -90, 45, uniform_volume) for _ in range(500)]) - [0, 0, 1]
    radius = np.linalg.norm(points, axis=1)
    elevation = np.degrees(np.arcsin(points[:, 2] / radius))
    azimuth = np.degrees(np.arctan2(points[:, 1], points[:, 0]))
    assert radius.min() >= 2 and radius.max() <= 3
    assert elevation.min() >= 15 - 1e-9 and elevation.max() <= 60 + 1e-9
    assert azimuth.min() >= -90 - 1e-9 and azimuth.max() <= 45 + 1e-9
    with pytest.raises(ValueError, match="azimuth"):
        sampler.shell([0, 0, 0], 1, 2, azimuth_min=-200)


def test_disk_sector_and_rotation() -> None:
    np.random.seed(3)
    sector = np.array([sampler.disk([0, 0, 0], 2, sample_from="sector", start_angle=20, end_angle=70)
                       for _ in range(300)])
    angles = np.degrees(np.arctan2(sector[:, 1], sector[:, 0]))
    assert angles.min() > 20 and angles.max() < 70 and np.abs(sector[:, 2]).max() == 0
    assert np.linalg.norm(sector, axis=1).max() <= 2
    upright = np.array([sampler.disk([0, 0, 1], 1, [np.pi / 2, 0, 0], "circle") for _ in range(50)])
    np.testing.assert_allclose(upright[:, 1], 0, atol=1e-12)  # the XY disk turned about X lies in the XZ plane
    np.testing.assert_allclose(np.linalg.norm(upright - [0, 0, 1], axis=1), 1, rtol=1e-12)
    with pytest.raises(ValueError, match="180"):
        sampler.disk([0, 0, 0], 1, sample_from="arc", start_angle=0, end_angle=200)


def _matrices(euler: np.ndarray) -> np.ndarray:
    return np.array([build_transformation_mat([0, 0, 0], angles)[:3, :3] for angles in euler])


def test_uniform_so3_is_blenderprocs_rotation_and_uniform() -> None:
    reference = bproc_reference.sampler("UniformSO3")
    for seed in range(5):
        for axes in [(True, True, True), (True, False, True), (False, False, True)]:
            mine, theirs = _same_draws(lambda: sampler.uniformSO3(*axes), lambda: reference.uniformSO3(*axes), seed)
            np.testing.assert_allclose(_matrices([mine]), _matrices([theirs]), atol=1e-12)
    np.random.seed(0)
    drawn = _matrices(np.array([sampler.uniformSO3() for _ in range(3000)]))
    scipy_drawn = Rotation.random(3000, random_state=1).as_matrix()
    assert np.abs(drawn.mean(axis=0)).max() < 0.05  # E[R] = 0 under the Haar measure
    angle = np.arccos(np.clip((np.trace(drawn, axis1=1, axis2=2) - 1) / 2, -1, 1))
    scipy_angle = np.arccos(np.clip((np.trace(scipy_drawn, axis1=1, axis2=2) - 1) / 2, -1, 1))
    assert stats.ks_2samp(angle, scipy_angle).pvalue > 0.01
    assert abs(np.mean(np.cos(angle)) + 0.5) < 0.03  # E[cos(angle)] = -1/2
    about_z = np.array([sampler.uniformSO3(False, False, True) for _ in range(200)])
    np.testing.assert_array_equal(about_z[:, :2], 0)


class _Box:
    """An object with BlenderProc's bounding-box corner order, axis-aligned from ``low`` to ``high``."""

    def __init__(self, low: list[float], high: list[float]) -> None:
        self.low, self.high = np.array(low, float), np.array(high, float)

    def get_bound_box(self) -> np.ndarray:
        low, high = self.low, self.high
        return np.array([[(low[0], high[0])[i >> 2], (low[1], high[1])[i in (2, 3, 6, 7)],
                          (low[2], high[2])[i in (1, 2, 5, 6)]] for i in range(8)])

    def get_local2world_mat(self) -> np.ndarray:
        return np.eye(4)

    def ray_cast(self, origin: np.ndarray, direction: np.ndarray) -> tuple[bool, None, None, None]:
        inside = bool(np.all(origin[:2] >= self.low[:2]) and np.all(origin[:2] <= self.high[:2]))
        return inside and direction[2] < 0 and origin[2] >= self.high[2], None, None, None


@pytest.mark.parametrize("seed", [0, 4])
def test_upper_region_draws_what_blenderproc_draws(seed: int) -> None:
    reference = bproc_reference.sampler("UpperRegionSampler")
    boxes = [_Box([0, 0, 0], [2, 1, 0.5]), _Box([-3, -3, 0], [-2, -1, 1])]
    for kwargs in [{}, {"face_sample_range": [0.2, 0.4], "min_height": 0.1, "max_height": 0.3},
                   {"upper_dir": [1, 0, 0.2], "use_upper_dir": False}, {"use_ray_trace_check": True}]:
        mine, theirs = _same_draws(lambda: sampler.upper_region(boxes, **kwargs),
                                   lambda: reference.upper_region(boxes, **kwargs), seed)
        np.testing.assert_allclose(mine, theirs, rtol=1e-12)


def test_upper_region_bounds() -> None:
    random.seed(2)
    box = _Box([1, 2, 0], [3, 5, 0.75])
    points = np.array([sampler.upper_region(box, min_height=0.5, max_height=1.0) for _ in range(300)])
    assert points[:, 0].min() >= 1 and points[:, 0].max() <= 3 and points[:, 1].min() >= 2 and points[:, 1].max() <= 5
    assert points[:, 2].min() >= 1.25 and points[:, 2].max() <= 1.75
    sideways = sampler.upper_region(box, max_height=0.0, upper_dir=[0, -1, 0])  # on the -Y face
    assert sideways[1] == 2 and 1 <= sideways[0] <= 3 and 0 <= sideways[2] <= 0.75


@pytest.mark.parametrize("seed", [0, 9])
def test_random_walk_is_blenderprocs(seed: int) -> None:
    reference = bproc_reference.sampler("RandomWalk")
    for kwargs in [dict(total_length=25, dims=1, step_magnitude=np.pi / 32, window_size=5,
                        interval=[-np.pi / 8, np.pi / 8], distribution="uniform", order=2),
                   dict(total_length=25, dims=3, window_size=10, distribution="normal"),
                   dict(total_length=30, dims=3, step_magnitude=0.05, window_size=5,
                        interval=[-np.ones(3) * 0.3, np.ones(3) * 0.3], distribution="uniform", order=4)]:
        mine, theirs = _same_draws(lambda: sampler.random_walk(**kwargs), lambda: reference.random_walk(**kwargs), seed)
        np.testing.assert_array_equal(mine, theirs)


def test_random_walk_bounds_and_smoothing() -> None:
    np.random.seed(1)
    walk = sampler.random_walk(400, 2, step_magnitude=0.3, interval=[np.zeros(2), np.ones(2)])
    assert walk.shape == (400, 2) and walk.min() >= 0 and walk.max() <= 1
    np.random.seed(1)
    raw = sampler.random_walk(50, 1)
    np.random.seed(1)
    smooth = sampler.random_walk(50, 1, window_size=3)
    np.testing.assert_allclose(smooth[2:, 0], (raw[:-2, 0] + raw[1:-1, 0] + raw[2:, 0]) / 3)
    np.testing.assert_allclose(smooth[0, 0], raw[0, 0])
    with pytest.raises(ValueError, match="distribution"):
        sampler.random_walk(3, 1, distribution="cauchy")


def _floor(name: str, low: list[float], high: list[float], cps: tuple[str, ...] = ("is_3D_future",)) -> SimpleNamespace:
    box = _Box(low, high)
    above = lambda point: bool(low[0] <= point[0] <= high[0] and low[1] <= point[1] <= high[1])  # noqa: E731
    return SimpleNamespace(get_name=lambda: name, has_cp=lambda key: key in cps, get_bound_box=box.get_bound_box,
                           get_location=lambda: np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]]),
                           position_is_above_object=above)


def test_room_samplers_are_blenderprocs(tmp_path: Any) -> None:
    front = bproc_reference.sampler("Front3DPointInRoomSampler")
    objects = [_floor("Floor.001", [0, 0, 0], [4, 3, 0]), _floor("floor.002", [5, 0, 0], [9, 2, 0]),
               _floor("Wall", [0, 0, 0], [1, 1, 2])]
    objects += [_floor(f"chair.{i}", [x, 1, 0.2], [x + 0.5, 1.5, 1]) for i, x in enumerate([0.5, 1.5, 2.5, 6])]
    ours, theirs = sampler.Front3DPointInRoomSampler(objects), front.Front3DPointInRoomSampler(objects)
    assert [f.get_name() for f in ours.used_floors] == ["Floor.001"]
    mine, reference = _same_draws(lambda: ours.sample(1.5), lambda: theirs.sample(1.5), 3)
    np.testing.assert_array_equal(mine, reference)
    assert 0 <= mine[0] <= 4 and 0 <= mine[1] <= 3 and mine[2] == 1.5
    heights = tmp_path / "heights.txt"
    heights.write_text("[0.0, 2.5]")
    replica = bproc_reference.sampler("ReplicaPointInRoomSampler")
    box = {"min": [0, 0, 0], "max": [6, 6, 5]}
    floors = [_floor("f", [0, 0, 0], [3, 6, 0]), _floor("g", [3, 0, 0], [4, 6, 0])]
    ours, theirs = (module.ReplicaPointInRoomSampler(box, floors, str(heights)) for module in (sampler, replica))
    mine, reference = _same_draws(lambda: ours.sample(1.0), lambda: theirs.sample(1.0), 6)
    np.testing.assert_array_equal(mine, reference)
    assert mine[0] <= 4 and mine[2] in (1.0, 3.5)
    with pytest.raises(NotImplementedError, match="SUNCG"):
        sampler.SuncgPointInRoomSampler([])
