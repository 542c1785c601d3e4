"""BlenderProc's CameraSampler view checks: min_interest_score (its scene coverage score, computed by hand
here for a known id image) and check_if_pose_above_object_list; module-level novelty keys reach every entry."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.errors import ConfigError, InputError
from hybridgen.sampling.interest_score import InterestScore
from tests.config.test_blenderproc_modules import HEADER, run_config_text


class _Obj:
    def __init__(self, instance_id: int, category_id: int | None, **attributes):
        self.instance_id, self.category_id, self.attributes = instance_id, category_id, attributes


def _thirds() -> np.ndarray:
    ids = np.zeros((30, 30), dtype=np.int32)
    ids[:, :10], ids[:, 10:20], ids[:, 20:] = 1, 2, 3
    return ids


def test_interest_score_by_hand():
    # 10 x 10 rays through columns 0, 3, 6 | 10, 13, 16 | 20, 23, 26, 29: hits 30, 30, 40 of 100
    objects = [_Obj(1, 1), _Obj(2, 2), _Obj(3, 3)]
    assert InterestScore.for_objects(objects, 0.1).score(_thirds()) == pytest.approx(3 / 3 * 0.7 * 0.7 * 0.6)
    special = InterestScore.for_objects(objects, 0.1, special=[3], weight=2.0)
    assert special.score(_thirds()) == pytest.approx(0.7 * 0.7 * 0.6 * (30 + 30 + 2 * 40) / 100)
    same_class = [_Obj(1, 7), _Obj(2, 7), _Obj(3, 3)]  # two objects of one category are one group
    assert InterestScore.for_objects(same_class, 0.1).score(_thirds()) == pytest.approx(2 / 3 * 0.4 * 0.6)
    walls = [_Obj(1, None, is_3d_front=True, type="Wall"), _Obj(2, None), _Obj(3, None, is_3d_front=True,
                                                                                 type="Object")]
    # a 3D-FRONT wall without category counts as its own object; furniture without class adds score only
    assert InterestScore.for_objects(walls, 0.1).score(_thirds()) == pytest.approx(2 / 3 * 0.7 * 0.7 * 1.0)
    one = np.ones((30, 30), dtype=np.int32)
    assert InterestScore.for_objects(objects, 0.1).score(one) == 0.0  # one object filling the view


SCENE = HEADER + """\
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "plane", "name": "floor", "scale": [10, 10, 1], "add_properties": {"cp_category_id": 1}},
    {"type": "cube", "name": "box", "scale": [0.5, 0.5, 0.5], "location": [0, 0, 0.5],
     "add_properties": {"cp_category_id": 2}}]}},
  {"module": "camera.CameraSampler", "config": {"max_tries": 3, "check_pose_novelty_translation": true,
    "min_var_diff_translation": -1, "intrinsics": {"fov": 0.9, "resolution_x": 32, "resolution_y": 24},
    "cam_poses": [{"location": LOCATION, "rotation": {"value": [0, 0, 0]}, CHECKS}]}}
]}
"""


def _sample(tmp_path, location, checks):
    text = SCENE.replace("LOCATION", location).replace("CHECKS", checks) % tmp_path
    return run_config_text(tmp_path, text).scene.camera


def test_interest_and_above_checks_accept_and_reject_views(tmp_path):
    interest = '"min_interest_score": 0.05'
    # straight down from 3 m above the box: box and floor share the view
    assert len(_sample(tmp_path, "[0, 0, 3]", interest)) == 1
    with pytest.raises(InputError, match="interest"):  # 5 m to the side: only floor
        _sample(tmp_path, "[5, 5, 3]", interest)
    above = '"check_if_pose_above_object_list": {"provider": "getter.Entity", "conditions": {"name": "box"}}'
    assert len(_sample(tmp_path, "[0.2, -0.3, 3]", above)) == 1
    with pytest.raises(InputError, match="above"):
        _sample(tmp_path, "[1.5, 0, 3]", above)


def test_interest_levels_as_blenderproc_lowers_them():
    from hybridgen.sampling.interest_score import interest_levels

    assert interest_levels(0.8, 1.0, 0.1) == [1.0, 0.9, 0.8]  # BlenderProc's documented example
    assert interest_levels(0.8) == [0.8] and interest_levels(0.8, 0.8, 0.5) == [0.8]
    assert interest_levels(0.8, 1.0, 0.3) == [1.0, 0.7]  # the last step may pass below the minimum
    assert interest_levels(0.0, 0.2, 0.1) == [0.2, 0.1, 0.0]  # 0: no check at the end


def test_interest_threshold_is_lowered_after_max_tries(tmp_path):
    # the view straight down from 3 m scores about 0.13 (box and floor share it): above every level from 0.95
    # down to 0.25 it is rejected 3 times per level (max_tries: 3); at 0.05 it is accepted
    schedule = '"min_interest_score": %s, "interest_score_range": 0.95, "interest_score_step": 0.1'
    assert len(_sample(tmp_path, "[0, 0, 3]", schedule % 0.05)) == 1
    with pytest.raises(InputError, match="interest"):
        _sample(tmp_path, "[0, 0, 3]", schedule % 0.25)
    with pytest.raises(InputError, match="interest"):  # no range: the minimum alone
        _sample(tmp_path, "[0, 0, 3]", '"min_interest_score": 0.95')
    with pytest.raises(ConfigError, match="interest_score_step"):
        _sample(tmp_path, "[0, 0, 3]", '"min_interest_score": 0.1, "interest_score_range": 0.5, '
                                       '"interest_score_step": 0')
