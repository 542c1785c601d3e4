"""bproc.object.replace_objects as BlenderProc's ObjectReplacer: a copy of the candidate takes each replaced
object's pose and the ratio of the local box sides as its scale, its custom properties, the replaced object
goes; a candidate that would intersect a neighbour is not placed."""
from __future__ import annotations

import random

import numpy as np

from writer_session import bproc  # noqa: F401 - the fixture


def _box(bproc, name: str, size: list[float], location: list[float]):  # noqa: F811
    obj = bproc.object.create_primitive("CUBE", size=1.0, location=location)
    obj.persist_transformation_into_mesh(location=False, rotation=False, scale=False)
    obj.parts[0].vertices = obj.parts[0].vertices * np.array(size)
    obj.set_name(name)
    return obj


def test_replacements_take_pose_scale_and_properties(bproc) -> None:  # noqa: F811
    random.seed(0)
    np.random.seed(0)
    chairs = [_box(bproc, "chair", [1.0, 1.0, 1.0], [x, 0.0, 0.5]) for x in (0.0, 5.0)]
    chairs[1].set_rotation_euler([0.0, 0.0, 0.7])
    for chair in chairs:
        chair.set_cp("category_id", 2)
    pool = _box(bproc, "tall", [2.0, 2.0, 4.0], [20.0, 0.0, 0.0])
    bproc.object.replace_objects(chairs, [pool])
    assert not any(chair.is_valid() for chair in chairs) and pool.is_hidden()
    copies = [obj for obj in bproc.object.get_all_mesh_objects() if obj is not pool]
    assert sorted(obj.get_name() for obj in copies) == ["tall.001", "tall.002"]
    for copy in copies:
        assert not copy.is_hidden() and copy.get_cp("category_id") == 2
        np.testing.assert_allclose(copy.get_scale(), [0.5, 0.5, 0.25])
        # the world box of each copy is the replaced chair's: 1 m cube at its location, turned as it was
        corners = copy.get_bound_box()
        assert np.ptp(corners[:, 2]) == 1.0 and corners[:, 2].min() == 0.0
    turned = next(c for c in copies if np.allclose(c.get_location(), [5.0, 0.0, 0.5]))
    np.testing.assert_allclose(turned.get_rotation_euler(), [0.0, 0.0, 0.7])


def test_a_colliding_candidate_is_not_placed(bproc) -> None:  # noqa: F811
    chair = _box(bproc, "chair", [1.0, 1.0, 1.0], [0.0, 0.0, 0.5])
    _box(bproc, "wall", [0.2, 4.0, 2.0], [0.6, 0.0, 1.0])  # touches the chair's place on its +x side
    wide = _box(bproc, "wide", [1.0, 1.0, 1.0], [20.0, 0.0, 0.0])

    def shift(obj) -> None:  # every try pushes the candidate into the wall
        obj.set_location(obj.get_location() + np.array([0.3, 0.0, 0.0]))

    bproc.object.replace_objects([chair], [wide], max_tries=3, relative_pose_sampler=shift)
    assert chair.is_valid() and [o.get_name() for o in bproc.object.get_all_mesh_objects()] == ["chair", "wall",
                                                                                               "wide"]
    bproc.object.replace_objects([chair], [wide], ignore_collision_with=[bproc.filter.one_by_attr(
        bproc.object.get_all_mesh_objects(), "name", "wall")], relative_pose_sampler=shift)
    assert not chair.is_valid()
