"""bproc's URDF kinematics against the real BlenderProc 2 (bpy 4.2): tests/bproc/data/urdf_blenderproc.json,
stored by tools/urdf_table.py, holds a five-joint robot's URDF, the joint-space calls made on it (forward
kinematics relative, absolute, clipped, per joint; an IK controller with a reachable goal, a controller turn it
cannot follow and an unreachable goal) and what BlenderProc answered: every bone's rest matrix, each keyed frame's
bone poses, visual poses and joint rotations, and has_reached_ik_pose. The same calls on hybridgen give the same
numbers (float32 rounding in Blender apart)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from writer_session import bproc  # noqa: F401 - the fixture

TABLE = json.loads((Path(__file__).parent / "data" / "urdf_blenderproc.json").read_text())


@pytest.fixture
def replayed(bproc, tmp_path: Path):  # noqa: F811
    """The robot after the table's calls, and the answers of has_reached_ik_pose."""
    (tmp_path / "robot.urdf").write_text(TABLE["urdf"])
    robot = bproc.loader.load_urdf(str(tmp_path / "robot.urdf"))
    answers = []
    for name, arguments in TABLE["ops"]:
        if arguments.get("link") is not None:
            arguments = {**arguments, "link": robot.links[arguments["link"]]}
        result = getattr(robot, name)(**arguments)
        if name == "has_reached_ik_pose":
            answers.append(result)
    return robot, answers


def test_bone_rest_matrices_are_blenders(replayed) -> None:
    robot, _ = replayed
    assert set(robot.armature.bones) == set(TABLE["rest"])
    for name, rest in TABLE["rest"].items():  # includes a bone along -Y exactly and a slanted one
        np.testing.assert_allclose(robot.armature.bones[name].rest(), rest, atol=1e-6, err_msg=name)


def test_each_frame_poses_bones_and_visuals_as_blenderproc(replayed) -> None:
    robot, answers = replayed
    assert answers == TABLE["reached"] == [True, False, False]
    for frame, expected in TABLE["frames"].items():
        np.testing.assert_allclose(robot.get_all_local2world_mats(frame=int(frame)), expected["joints"],
                                   atol=1e-4, err_msg=f"frame {frame}")
        np.testing.assert_allclose(robot.get_all_visual_local2world_mats(frame=int(frame)), expected["visuals"],
                                   atol=1e-4, err_msg=f"frame {frame}")
        rotations = [link.get_joint_rotation(int(frame)) for link in robot.links]
        np.testing.assert_allclose(rotations, expected["joint_rotations"], atol=1e-3, err_msg=f"frame {frame}")
