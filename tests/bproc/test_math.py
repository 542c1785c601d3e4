"""bproc.math against hand-computed matrices and SciPy's rotations."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hybridgen.bproc import math as bmath
from hybridgen.scene.frames import opencv_to_blender


def test_build_transformation_mat_from_euler_is_blender_xyz() -> None:
    matrix = bmath.build_transformation_mat([1.0, 2.0, 3.0], [np.pi / 2, 0.0, 0.0])
    expected = np.array([[1, 0, 0, 1], [0, 0, -1, 2], [0, 1, 0, 3], [0, 0, 0, 1]], dtype=float)
    np.testing.assert_allclose(matrix, expected, atol=1e-15)
    angles = [0.3, -1.1, 2.5]  # R = Rz(2.5) Ry(-1.1) Rx(0.3)
    turned = bmath.build_transformation_mat(np.array([[0.5], [0.0], [-1.0]]), np.array(angles).reshape(3, 1))
    hand = Rotation.from_euler("z", 2.5).as_matrix() @ Rotation.from_euler("y", -1.1).as_matrix() \
        @ Rotation.from_euler("x", 0.3).as_matrix()
    np.testing.assert_allclose(turned[:3, :3], hand, atol=1e-15)
    np.testing.assert_array_equal(turned[:3, 3], [0.5, 0.0, -1.0])
    np.testing.assert_array_equal(turned[3], [0, 0, 0, 1])


def test_build_transformation_mat_takes_a_rotation_matrix_and_rejects_other_shapes() -> None:
    rotation = Rotation.from_rotvec([0.2, 0.4, -0.3]).as_matrix()
    matrix = bmath.build_transformation_mat([0, 0, 1], rotation)
    np.testing.assert_array_equal(matrix[:3, :3], rotation)
    with pytest.raises(ValueError, match="translation"):
        bmath.build_transformation_mat([0, 1], rotation)
    with pytest.raises(ValueError, match="rotation"):
        bmath.build_transformation_mat([0, 0, 1], np.eye(4))


def test_change_coordinate_frame_of_point() -> None:
    np.testing.assert_array_equal(bmath.change_coordinate_frame_of_point([1, 2, 3], ["X", "-Z", "Y"]), [1, -3, 2])
    np.testing.assert_array_equal(bmath.change_coordinate_frame_of_point([1.5, 2, 3], ["-y", "x", "-x"]),
                                  [-2, 1.5, -1.5])
    with pytest.raises(ValueError, match="three axes"):
        bmath.change_coordinate_frame_of_point([1, 2, 3], ["X", "Y"])
    with pytest.raises(ValueError, match="invalid axis"):
        bmath.change_coordinate_frame_of_point([1, 2, 3], ["X", "Y", "W"])


def test_change_source_frame_turns_an_opencv_pose_into_blender_axes() -> None:
    opencv = np.array([[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 3], [0, 0, 0, 1]], dtype=float)  # 3 m up, looking down
    blender = bmath.change_source_coordinate_frame_of_transformation_matrix(opencv, ["X", "-Y", "-Z"])
    np.testing.assert_array_equal(blender, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1]])
    pose = bmath.build_transformation_mat([0.3, -2, 1], [0.4, 0.1, -0.7])
    np.testing.assert_array_equal(
        bmath.change_source_coordinate_frame_of_transformation_matrix(pose, ["X", "-Y", "-Z"]), opencv_to_blender(pose))
    # A' axes (x' = z, y' = -x, z' = y): the new source's x axis is the old z axis, so column 0 is old column 2
    swapped = bmath.change_source_coordinate_frame_of_transformation_matrix(pose, ["Z", "-X", "Y"])
    np.testing.assert_array_equal(swapped[:, 0], pose[:, 2])
    np.testing.assert_array_equal(swapped[:, 1], -pose[:, 0])
    np.testing.assert_array_equal(swapped[:, 2], pose[:, 1])


def test_change_target_frame_moves_points_into_the_new_frame() -> None:
    pose = bmath.build_transformation_mat([0.3, -2, 1], [0.4, 0.1, -0.7])
    changed = bmath.change_target_coordinate_frame_of_transformation_matrix(pose, ["X", "-Z", "Y"])
    np.testing.assert_array_equal(changed[0], pose[0])
    np.testing.assert_array_equal(changed[1], -pose[2])
    np.testing.assert_array_equal(changed[2], pose[1])
    point = np.array([0.5, 0.25, -1.0, 1.0])
    np.testing.assert_allclose((changed @ point)[:3],
                               bmath.change_coordinate_frame_of_point((pose @ point)[:3], ["X", "-Z", "Y"]))


def test_blender_euler_round_trips_and_picks_the_smaller_triple() -> None:
    rng = np.random.default_rng(7)
    for rotation in Rotation.random(200, random_state=rng).as_matrix():
        angles = bmath.blender_euler_from_matrix(rotation)
        np.testing.assert_allclose(bmath.build_transformation_mat([0, 0, 0], angles)[:3, :3], rotation, atol=1e-12)
    # (3, 0.1, 3) and (3 - pi, pi - 0.1, 3 - pi) are the same rotation; Blender returns the second (sum 3.32 < 6.1)
    flipped = bmath.blender_euler_from_matrix(Rotation.from_euler("xyz", [3.0, 0.1, 3.0]).as_matrix())
    np.testing.assert_allclose(flipped, [3.0 - np.pi, np.pi - 0.1, 3.0 - np.pi], atol=1e-12)
    kept = bmath.blender_euler_from_matrix(Rotation.from_euler("xyz", [0.5, -0.2, 1.0]).as_matrix())
    np.testing.assert_allclose(kept, [0.5, -0.2, 1.0], atol=1e-12)
    # gimbal lock (b = pi/2): only a - c is defined and Blender sets c = 0
    locked = bmath.blender_euler_from_matrix(Rotation.from_euler("xyz", [0.3, np.pi / 2, 0.2]).as_matrix())
    np.testing.assert_allclose(locked, [0.1, np.pi / 2, 0.0], atol=1e-7)


def test_quaternion_is_w_first_and_normalised() -> None:
    wxyz = np.array([0.9, 0.1, -0.3, 0.2])
    expected = Rotation.from_quat([0.1, -0.3, 0.2, 0.9]).as_matrix()
    np.testing.assert_allclose(bmath.matrix_from_blender_quaternion(2.0 * wxyz), expected, atol=1e-15)
