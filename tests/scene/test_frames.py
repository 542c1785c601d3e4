"""docs/conventions.md section 1: frames, look-at, Euler, source frames."""
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.scene.frames import (blender_to_opencv, euler_xyz_to_matrix, forward_to_rotation_blender,
                                    look_at_blender, source_frame_matrix)


def test_look_at_matches_spec_vector():
    expected = np.array([[-0.8944, -0.3586, 0.2673], [0.4472, -0.7171, 0.5345], [0.0, 0.5976, 0.8018]])
    np.testing.assert_allclose(look_at_blender([1, 2, 3], [0, 0, 0]), expected, atol=1e-4)


def test_look_at_opencv_axes_point_at_target():
    pose = hg.look_at([1, 2, 3], [0, 0, 0])
    forward = pose[:3, 2]
    np.testing.assert_allclose(forward, -np.array([1, 2, 3]) / np.sqrt(14), atol=1e-12)
    # image "down" (+y) has a negative world-Z component: image up is as close as possible to +Z
    assert pose[2, 1] < 0
    assert abs(pose[:3, 0] @ [0, 0, 1]) < 1e-12  # no roll: x axis horizontal


def test_blender_to_opencv_flips_y_and_z():
    pose = np.eye(4)
    pose[:3, 3] = [1, 2, 3]
    cv = blender_to_opencv(pose)
    np.testing.assert_allclose(cv[:3, :3], np.diag([1, -1, -1]))
    np.testing.assert_allclose(cv[:3, 3], [1, 2, 3])


def test_source_frame_blender_equals_builtin_conversion():
    pose = np.eye(4)
    pose[:3, :3] = euler_xyz_to_matrix([0.3, -0.2, 1.1])
    np.testing.assert_allclose(pose @ source_frame_matrix(["X", "-Y", "-Z"]), blender_to_opencv(pose))
    np.testing.assert_allclose(source_frame_matrix(["X", "Y", "Z"]), np.eye(4))
    with pytest.raises(ValueError):
        source_frame_matrix(["X", "X", "Z"])


def test_euler_xyz_order():
    # Blender XYZ: first about X, then Y, then Z (R = Rz Ry Rx)
    r = euler_xyz_to_matrix([np.pi / 2, 0, np.pi / 2])
    np.testing.assert_allclose(r @ [0, 1, 0], [0, 0, 1], atol=1e-12)  # X turns y to z; Z keeps z
    np.testing.assert_allclose(r @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_inplane_rotation_rolls_about_view_axis():
    base = forward_to_rotation_blender([1, 0, 0])
    rolled = forward_to_rotation_blender([1, 0, 0], inplane_rot=np.pi / 2)
    np.testing.assert_allclose(rolled[:, 2], base[:, 2], atol=1e-12)  # same view direction
    np.testing.assert_allclose(rolled[:, 0], base[:, 1], atol=1e-12)  # x turned onto the old y


def test_looking_straight_down_is_defined():
    rot = look_at_blender([0, 0, 5], [0, 0, 0])
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(rot[:, 2], [0, 0, 1], atol=1e-12)
