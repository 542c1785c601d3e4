"""URDF kinematics of bproc's URDFObject against analytic truth: a planar arm whose joints turn about world Z, so
every joint position and link direction follows from the joint angles by trigonometry. Forward kinematics
(absolute, relative, limits, one joint or all), frames keyed per call and rendered (which link covers which pixel
in an instance segmentation seen from above), inverse kinematics to a reachable goal (the law of cosines) and an
unreachable one, and removing a link."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from writer_session import bproc  # noqa: F401 - the fixture

from hybridgen.errors import InputError

UPPER, FORE = 0.5, 0.4
"""Link lengths (m): shoulder to elbow, elbow to wrist."""

ARM = f"""<?xml version="1.0"?>
<robot name="planar">
  <link name="base"><visual><geometry><mesh filename="base.obj"/></geometry></visual></link>
  <joint name="shoulder" type="revolute"><origin xyz="0 0 0.1"/><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <link name="upper"><visual><geometry><mesh filename="upper.obj"/></geometry></visual></link>
  <joint name="elbow" type="revolute"><origin xyz="{UPPER} 0 0"/><parent link="upper"/><child link="fore"/>
    <axis xyz="0 0 1"/><limit lower="-2.8" upper="2.8" effort="1" velocity="1"/></joint>
  <link name="fore"><visual><geometry><mesh filename="fore.obj"/></geometry></visual></link>
  <joint name="wrist" type="revolute"><origin xyz="{FORE} 0 0"/><parent link="fore"/><child link="hand"/>
    <axis xyz="0 0 1"/><limit lower="-2.8" upper="2.8" effort="1" velocity="1"/></joint>
  <link name="hand"><visual><geometry><mesh filename="hand.obj"/></geometry></visual></link>
</robot>
"""


def _box_obj(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> str:
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    return "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {a} {b} {c} {d}\n"
                                                                         for a, b, c, d in faces)


@pytest.fixture
def arm(bproc, tmp_path: Path):  # noqa: F811
    """The planar arm, its world link-less root ``base`` at the origin; links: base, upper, fore, hand."""
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "base.obj").write_text(_box_obj((-0.05, -0.05, 0.0), (0.05, 0.05, 0.1)))
    (tmp_path / "upper.obj").write_text(_box_obj((0.05, -0.03, -0.03), (UPPER - 0.05, 0.03, 0.03)))
    (tmp_path / "fore.obj").write_text(_box_obj((0.05, -0.03, -0.03), (FORE - 0.05, 0.03, 0.03)))
    (tmp_path / "hand.obj").write_text(_box_obj((0.0, -0.02, -0.02), (0.1, 0.02, 0.02)))
    return bproc.loader.load_urdf(str(tmp_path / "arm.urdf"))


def _heads(robot, frame: int | None = None) -> np.ndarray:
    """World positions of the joints shoulder, elbow, wrist (m)."""
    return robot.get_all_local2world_mats(frame=frame)[:, :3, 3]


def _expected_heads(angles: tuple[float, float]) -> np.ndarray:
    a, b = angles
    elbow = np.array([UPPER * math.cos(a), UPPER * math.sin(a), 0.1])
    return np.array([[0, 0, 0.1], elbow, elbow + [FORE * math.cos(a + b), FORE * math.sin(a + b), 0.0]])


def test_forward_kinematics_of_a_planar_arm(arm) -> None:
    shoulder, elbow = 0.7, -1.1
    arm.set_rotation_euler_fk(link=None, rotation_euler=[shoulder, elbow, 0.3], mode="absolute", frame=0)
    np.testing.assert_allclose(_heads(arm), _expected_heads((shoulder, elbow)), atol=1e-9)
    bones = arm.get_all_local2world_mats()
    np.testing.assert_allclose(bones[:, :3, 1], np.tile([0, 0, 1], (3, 1)), atol=1e-9)  # each bone's Y: the axis
    # a link's visual turns with its joint: the fore arm's box points along the sum of the angles
    fore = arm.links[2].get_visuals()[0].get_local2world_mat()
    np.testing.assert_allclose(fore[:3, 0], [math.cos(shoulder + elbow), math.sin(shoulder + elbow), 0], atol=1e-9)
    np.testing.assert_allclose(fore[:3, 3], _expected_heads((shoulder, elbow))[1], atol=1e-9)
    hand = arm.links[3].get_visuals()[0].get_local2world_mat()
    turn = shoulder + elbow + 0.3
    np.testing.assert_allclose(hand[:3, 0], [math.cos(turn), math.sin(turn), 0], atol=1e-9)
    np.testing.assert_allclose(arm.get_all_visual_local2world_mats()[2, 0], fore, atol=1e-9)
    assert arm.links[1].get_joint_rotation() == pytest.approx(shoulder)


def test_absolute_relative_and_limits(arm) -> None:
    upper = arm.links[1]
    arm.set_rotation_euler_fk(link=upper, rotation_euler=5.0, mode="absolute", frame=0)  # clipped to the limit 2
    np.testing.assert_allclose(_heads(arm)[1], _expected_heads((2.0, 0.0))[1], atol=1e-9)
    arm.set_rotation_euler_fk(link=upper, rotation_euler=1.9, mode="absolute", frame=1)
    arm.set_rotation_euler_fk(link=upper, rotation_euler=0.3, mode="relative", frame=2)  # 2.2 asked, held at 2
    np.testing.assert_allclose(_heads(arm)[1], _expected_heads((2.0, 0.0))[1], atol=1e-9)
    arm.set_rotation_euler_fk(link=upper, rotation_euler=-0.1, mode="relative", frame=3)  # 2.1: still held
    np.testing.assert_allclose(_heads(arm)[1], _expected_heads((2.0, 0.0))[1], atol=1e-9)
    arm.set_rotation_euler_fk(link=None, rotation_euler=-0.2, mode="relative", frame=4)  # every joint: 1.9, -0.2
    np.testing.assert_allclose(_heads(arm), _expected_heads((1.9, -0.2)), atol=1e-9)
    # each frame keeps its own pose
    for frame, angles in ((0, (2.0, 0.0)), (1, (1.9, 0.0)), (2, (2.0, 0.0)), (4, (1.9, -0.2))):
        np.testing.assert_allclose(_heads(arm, frame), _expected_heads(angles), atol=1e-9)
    with pytest.raises(InputError, match="mode must be 'absolute' or 'relative'"):
        arm.set_rotation_euler_fk(link=upper, rotation_euler=0.1, mode="sideways")


def test_each_frame_renders_its_own_pose(arm, bproc) -> None:  # noqa: F811
    arm.set_rotation_euler_fk(link=None, rotation_euler=[0.0, 0.0, 0.0], mode="absolute", frame=0)
    arm.set_rotation_euler_fk(link=None, rotation_euler=[math.pi / 2, 0.0, 0.0], mode="absolute", frame=1)
    assert bproc.utility.num_frames() == 1  # BlenderProc's keying grows the range only past its end (1 > 0)
    bproc.camera.set_resolution(64, 64)
    view = np.eye(4)  # looking straight down from 2 m above the shoulder
    view[:3, 3] = [0.0, 0.0, 2.1]
    bproc.camera.add_camera_pose(view, frame=0)
    bproc.camera.add_camera_pose(view, frame=1)
    assert bproc.utility.num_frames() == 2
    data = bproc.renderer.render_segmap(map_by=["instance", "name"])
    along_x, along_y = [0.3, 0.0, 0.13], [0.0, 0.3, 0.13]  # on the upper arm's top at 0 and at 90 degrees
    for frame, covered, empty in ((0, along_x, along_y), (1, along_y, along_x)):
        names = {entry["idx"]: entry["name"] for entry in data["instance_attribute_maps"][frame]}
        u, v = np.round(bproc.camera.project_points(np.array([covered, empty]), frame=frame) - 0.5).astype(int)
        segmap = data["instance_segmaps"][frame]
        assert names.get(int(segmap[u[1], u[0]])) == "upper_visual"
        assert names.get(int(segmap[v[1], v[0]])) != "upper_visual"


def test_inverse_kinematics_reaches_a_reachable_goal_and_not_an_unreachable_one(arm) -> None:
    arm.create_ik_bone_controller(link=arm.links[3])  # the hand; the goal is its wrist joint
    goal = np.array([0.6, 0.3, 0.1])
    arm.set_location_ik(goal, frame=0)
    assert arm.has_reached_ik_pose(location_error=0.001, rotation_error=0.001)
    shoulder, elbow, wrist = _heads(arm)
    np.testing.assert_allclose(wrist, goal, atol=1e-3)
    assert np.linalg.norm(elbow - shoulder) == pytest.approx(UPPER, abs=1e-9)
    reach = np.linalg.norm(goal - shoulder)  # the elbow's bend, by the law of cosines
    bend = math.pi - math.acos((UPPER ** 2 + FORE ** 2 - reach ** 2) / (2 * UPPER * FORE))
    upper_dir, fore_dir = (elbow - shoulder) / UPPER, (wrist - elbow) / FORE
    assert math.acos(np.clip(upper_dir @ fore_dir, -1, 1)) == pytest.approx(bend, abs=2e-3)
    # the hand keeps the controller's orientation: its rest orientation, so it points along +X again
    hand = arm.links[3].get_visuals()[0].get_local2world_mat()
    np.testing.assert_allclose(hand[:3, 0], [1, 0, 0], atol=2e-3)
    arm.set_rotation_euler_ik(rotation_euler=[0.0, 0.4, 0.0], mode="relative", frame=1)  # about the bone's Y: Z
    assert arm.has_reached_ik_pose(location_error=0.001, rotation_error=0.001)
    hand = arm.links[3].get_visuals()[0].get_local2world_mat()
    np.testing.assert_allclose(hand[:3, 0], [math.cos(0.4), math.sin(0.4), 0], atol=2e-3)
    np.testing.assert_allclose(_heads(arm)[2], goal, atol=1e-3)
    arm.set_location_ik([2.0, 0.0, 0.1], frame=2)  # beyond the arm's reach of 0.9 m
    assert not arm.has_reached_ik_pose(location_error=0.01, rotation_error=0.01)
    assert np.linalg.norm(_heads(arm)[2] - [2.0, 0.0, 0.1]) > 1.0
    np.testing.assert_allclose(_heads(arm, 1)[2], goal, atol=1e-3)  # frame 1 kept its pose


def test_removing_a_link_moves_its_child_chain_into_its_place(arm) -> None:
    upper, fore = arm.links[1], arm.links[2]
    upper_visual = upper.get_visuals()[0]
    arm.remove_link_by_index(1)
    assert arm.links == [arm.links[0], fore, arm.links[2]] and not upper_visual.is_valid()
    np.testing.assert_allclose(_heads(arm)[0], [0, 0, 0.1], atol=1e-9)  # the elbow now sits on the shoulder
    arm.set_rotation_euler_fk(link=fore, rotation_euler=0.3, mode="absolute", frame=0)
    visual = fore.get_visuals()[0].get_local2world_mat()
    np.testing.assert_allclose(visual[:3, 3], [0, 0, 0.1], atol=1e-9)
    np.testing.assert_allclose(visual[:3, 0], [math.cos(0.3), math.sin(0.3), 0], atol=1e-9)
    np.testing.assert_allclose(_heads(arm)[1], [FORE * math.cos(0.3), FORE * math.sin(0.3), 0.1], atol=1e-9)
    with pytest.raises(InputError, match="Invalid index 5"):
        arm.remove_link_by_index(5)


def test_unsupported_uses_are_one_line(arm) -> None:
    with pytest.raises(InputError, match="no IK bone controller"):
        arm.set_location_ik([0.1, 0.0, 0.0])
    with pytest.raises(InputError, match="use set_rotation_euler_fk"):
        arm.links[1].set_rotation_euler([0, 0, 1])
    arm.create_ik_bone_controller()
    with pytest.raises(InputError, match="already has an IK controller"):
        arm.create_ik_bone_controller()


def test_robot_types_are_bproc_types(arm, bproc) -> None:  # noqa: F811
    """``bproc.types.URDFObject`` (and BlenderProc's internal ``LinkUtility.Link`` / ``URDFUtility.URDFObject``) are
    the classes load_urdf's robot and links are; Armature stays a one-line stand-in."""
    from hybridgen.bproc.internal_modules import internal_module

    assert isinstance(arm, bproc.types.URDFObject)
    assert all(isinstance(link, bproc.types.Link) for link in arm.links)
    URDFObject = internal_module("blenderproc.python.types.URDFUtility", "hybridgen.bproc").URDFObject  # noqa: N806
    Link = internal_module("blenderproc.python.types.LinkUtility", "hybridgen.bproc").Link  # noqa: N806
    assert URDFObject is bproc.types.URDFObject and Link is bproc.types.Link
    with pytest.raises(InputError, match="bproc.types.Armature is not supported by hybridgen yet"):
        bproc.types.Armature()
