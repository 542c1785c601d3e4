"""bproc.camera's projections against analytic truth: ray-cast depth and distance of a floor seen from above, the
point cloud of that depth lying on the floor, project_points inverting unproject_points (BlenderProc's y flip),
and bproc.object.create_from_point_cloud's points and visualization."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture


def _down_at(bproc, height: float, x: float = 0.0) -> None:  # noqa: F811
    pose = np.eye(4)  # Blender camera axes: looking along world -Z, image up = world +Y
    pose[:3, 3] = [x, 0.0, height]
    bproc.camera.add_camera_pose(pose)


def test_depth_and_distance_of_a_floor(bproc) -> None:  # noqa: F811
    floor = bproc.object.create_primitive("PLANE", size=4)  # x, y in -2..2
    _down_at(bproc, 3.0, x=1.0)
    tree = bproc.object.create_bvh_tree_multi_objects([floor])
    depth = bproc.camera.depth_via_raytracing(tree, 0)
    distance = bproc.camera.depth_via_raytracing(tree, 0, return_dist=True)
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    x, y = 1.0 + (u - K[0, 2]) / K[0, 0] * 3.0, -(v - K[1, 2]) / K[1, 1] * 3.0  # pixel centres on z = 0
    on_floor = (np.abs(x) < 2) & (np.abs(y) < 2)
    assert depth.shape == (24, 32) and 0 < on_floor.sum() < on_floor.size
    np.testing.assert_allclose(depth[on_floor], 3.0, rtol=1e-9)
    assert np.isinf(depth[~on_floor]).all() and np.isinf(distance[~on_floor]).all()
    np.testing.assert_allclose(distance[on_floor], np.sqrt(x * x - 2 * x + 1 + y * y + 9)[on_floor], rtol=1e-9)
    points = bproc.camera.pointcloud_from_depth(depth, 0)
    np.testing.assert_allclose(points[on_floor], np.stack([x, y, np.zeros_like(x)], -1)[on_floor], atol=1e-9)
    assert np.isnan(points[~on_floor]).all()  # inf depth is beyond the cut-off


def test_project_points_inverts_unproject_points(bproc) -> None:  # noqa: F811
    bproc.camera.add_camera_pose(bproc.math.build_transformation_mat([0.5, -4.0, 2.0], [1.2, 0.1, 0.3]))
    pixels = np.array([[0.0, 0.0], [31.0, 23.0], [10.25, 7.5]])
    world = bproc.camera.unproject_points(pixels.copy(), np.array([2.0, 3.5, 1.0]), 0)
    np.testing.assert_allclose(bproc.camera.project_points(world, 0), pixels, atol=1e-9)
    flipped = pixels.copy()
    bproc.camera.unproject_points(flipped, np.ones(3), 0)
    np.testing.assert_allclose(flipped[:, 1], 23 - pixels[:, 1])  # BlenderProc flips the caller's y in place


def test_point_cloud_objects(bproc) -> None:  # noqa: F811
    points = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.5], [np.nan, 0.0, 0.0], [-1.0, 0.5, 2.0]])
    plain = bproc.object.create_from_point_cloud(points, "cloud")
    assert plain.parts == [] and plain.get_name() == "cloud"
    np.testing.assert_allclose(plain.get_bound_box().min(axis=0), [-1.0, 0.0, 0.0])
    np.testing.assert_allclose(plain.get_bound_box().max(axis=0), [1.0, 2.0, 2.0])
    shown = bproc.object.create_from_point_cloud(points, "cloud", add_geometry_nodes_visualization=True)
    assert shown.get_name() == "cloud.001" and len(shown.parts[0].faces) == 3 * 20
    vertices = shown.parts[0].vertices.reshape(3, 12, 3)
    np.testing.assert_allclose(np.linalg.norm(vertices - points[[0, 1, 3], None], axis=2), 0.015)
    material = shown.get_materials()[0]
    assert material.get_name() == "point_cloud_mat"
    assert material.get_principled_shader_value("Base Color")[:3] == pytest.approx([1, 0, 0])
