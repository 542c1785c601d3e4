"""bproc.object.sample_poses / sample_poses_on_surface: BlenderProc's return values, try counts, failure modes and
the bound-box drop, checked against hand-computed poses."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture


def test_sample_poses_counts_tries_and_avoids_obstacles(bproc) -> None:  # noqa: F811
    wall = bproc.object.create_primitive("CUBE", size=2.0)  # occupies -1..1 on every axis
    box = bproc.object.create_primitive("CUBE", size=0.5)
    spots = iter([[0.5, 0, 0], [1.0, 0, 0], [3.0, 0, 0]])  # inside, touching-through, free
    result = bproc.object.sample_poses([box], lambda obj: obj.set_location(next(spots)))
    assert result == {box: (2, True)}  # the index of the successful try, as BlenderProc returns it
    assert np.allclose(box.get_location(), [3, 0, 0])
    assert np.allclose(wall.get_location(), 0)


@pytest.mark.parametrize("mode, expected", [("last_pose", [0.2, 0, 0]), ("initial_pose", [7.0, 0, 0])])
def test_sample_poses_failure_modes(bproc, mode: str, expected: list[float]) -> None:  # noqa: F811
    bproc.object.create_primitive("CUBE", size=2.0)
    box = bproc.object.create_primitive("CUBE", size=0.5, location=[7, 0, 0])
    spots = iter([[0.0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]])
    result = bproc.object.sample_poses([box], lambda obj: obj.set_location(next(spots)), max_tries=3,
                                       mode_on_failure=mode)
    assert result == {box: (3, False)}
    assert np.allclose(box.get_location(), expected)


def test_later_objects_avoid_earlier_ones(bproc) -> None:  # noqa: F811
    first, second = (bproc.object.create_primitive("CUBE", size=1.0) for _ in range(2))
    spots = iter([[0, 0, 5], [0.5, 0, 5], [2, 0, 5]])  # second's first try overlaps first
    result = bproc.object.sample_poses([first, second], lambda obj: obj.set_location(next(spots)),
                                       objects_to_check_collisions=[])
    assert result == {first: (0, True), second: (1, True)}
    assert np.allclose(second.get_location(), [2, 0, 5])


def test_on_surface_drops_the_bound_box_onto_the_surface(bproc) -> None:  # noqa: F811
    table = bproc.object.create_primitive("CUBE", size=2.0, location=[0, 0, -1])  # top face at z = 0
    cube = bproc.object.create_primitive("CUBE", size=0.2)
    tilt = 0.3  # rad about x: the local box's lowest corner is 0.1 (cos + sin) below the centre

    def pose(obj) -> None:
        obj.set_location([0.2, 0.1, 3.0])
        obj.set_rotation_euler([tilt, 0, 0])

    placed = bproc.object.sample_poses_on_surface([cube], table, pose, max_tries=5)
    assert placed == [cube]
    expected_z = 0.1 * (np.cos(tilt) + np.sin(tilt))
    assert np.allclose(cube.get_location(), [0.2, 0.1, expected_z])
    assert np.allclose(cube.get_rotation_euler(), [tilt, 0, 0])


def test_on_surface_failure_hides_and_restores(bproc) -> None:  # noqa: F811
    table = bproc.object.create_primitive("CUBE", size=2.0, location=[0, 0, -1])
    first = bproc.object.create_primitive("CUBE", size=0.2)
    second = bproc.object.create_primitive("CUBE", size=0.2, location=[9, 9, 9])
    spots = iter([[0, 0, 2], [5, 0, 2], [0.1, 0, 2], [0.9, 0, 2]])  # off the table; too close; too far (0.9 > 0.6)

    def pose(obj) -> None:
        obj.set_location(next(spots))

    placed = bproc.object.sample_poses_on_surface([first, second], table, pose, max_tries=3)
    assert placed == [first] and not first.is_hidden()
    assert np.allclose(first.get_location(), [0, 0, 0.1])
    assert second.is_hidden() and np.allclose(second.get_location(), [9, 9, 9])
