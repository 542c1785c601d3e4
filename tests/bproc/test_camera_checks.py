"""bproc.camera's view checks and lens model against analytic truth: the ray grid of visible_objects /
scene_coverage_score over two floor halves seen from above, perform_obstacle_in_view_check over a plane at a known
distance, is_point_inside_camera_frustum, set_lens_distortion's mapping (it must distort back onto every pixel)
and add_depth_of_field's thin lens (Blender's aperture lens / (2 f-stop), the focus following its object);
get_camera_frustum against BlenderProc's inverse perspective matrix and its object's volume."""
from __future__ import annotations

import math

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture

DOWN = np.eye(4)  # Blender camera axes: identity looks along world -Z, image up = world +Y


def _camera_at(bproc, height: float) -> np.ndarray:  # noqa: F811
    pose = DOWN.copy()
    pose[2, 3] = height
    bproc.camera.add_camera_pose(pose)
    return pose


def _two_halves(bproc) -> tuple:  # noqa: F811
    """Two 10 m plates: x < 0 (category 1) and x > 0 (category 2), at z = 0."""
    left = bproc.object.create_primitive("PLANE", size=10, location=[-5, 0, 0])
    right = bproc.object.create_primitive("PLANE", size=10, location=[5, 0, 0])
    left.set_cp("category_id", 1)
    right.set_cp("category_id", 2)
    return left, right


def test_visible_objects_and_coverage_score(gl_context, bproc) -> None:  # noqa: F811
    left, right = _two_halves(bproc)
    pose = _camera_at(bproc, 3.0)
    assert bproc.camera.visible_objects(pose) == {left, right}
    # 50 rays on each category: (2 / 3) * (1 - 1/2)^2 * (100 / 100)
    assert bproc.camera.scene_coverage_score(pose) == pytest.approx(1 / 6)
    # category 2 special (weight 2): the ray weights sum to 150
    assert bproc.camera.scene_coverage_score(pose, special_objects=[2]) == pytest.approx(1 / 6 * 1.5)
    shifted = pose.copy()
    shifted[0, 3] = 20.0  # only the right plate below (its edge at x = 10 outside a 3 m-high view of +-1 m)
    assert bproc.camera.visible_objects(shifted) == set()
    shifted[0, 3] = 6.0
    assert bproc.camera.visible_objects(shifted) == {right}
    assert bproc.camera.scene_coverage_score(shifted) == pytest.approx(0.0)  # (1/3) * (1 - 1) * 1
    assert bproc.camera.decrease_interest_score(0.5, 0.2, 0.1) == (True, pytest.approx(0.4))
    assert bproc.camera.decrease_interest_score(0.2, 0.2, 0.1) == (False, 0.2)


class _PlaneTree:
    """A BVH stand-in: the plane z = 0, hit distances computed analytically (Blender's ray_cast tuple)."""

    def ray_cast(self, origin, direction, distance=math.inf):
        origin, direction = np.asarray(origin, float), np.asarray(direction, float)
        unit = direction / np.linalg.norm(direction)
        if unit[2] >= 0:
            return None, None, None, None
        along = -origin[2] / unit[2]
        if along > distance:
            return None, None, None, None
        return origin + along * unit, np.array([0, 0, 1.0]), 0, along


def test_obstacle_in_view_check_on_a_plane_at_a_known_distance(bproc) -> None:  # noqa: F811
    pose = DOWN.copy()
    pose[2, 3] = 2.0
    tree = _PlaneTree()
    # 3 x 3 grid: the centre ray hits at exactly 2 m; a corner ray at 2 / cos(corner angle)
    fx = bproc.camera.get_intrinsics_as_K_matrix()[0, 0]
    half_w, half_h = 16 / fx, 12 / fx  # image edges at -0.5 and W - 0.5 around the centre (W - 1) / 2
    corner = 2.0 * math.sqrt(1 + half_w ** 2 + half_h ** 2)
    edges = [2.0 * math.sqrt(1 + half_w ** 2), 2.0 * math.sqrt(1 + half_h ** 2)]
    check = bproc.camera.perform_obstacle_in_view_check
    assert check(pose, {"min": 1.99}, tree, 3)
    assert not check(pose, {"min": 2.0}, tree, 3)  # BlenderProc fails at dist <= min
    assert check(pose, {"max": corner + 1e-6}, tree, 3)
    assert not check(pose, {"max": corner - 1e-6}, tree, 3)
    mean = (2.0 + 2 * edges[0] + 2 * edges[1] + 4 * corner) / 9
    assert check(pose, {"avg": {"min": mean - 1e-6, "max": mean + 1e-6}}, tree, 3)
    assert not check(pose, {"avg": {"min": mean + 1e-6, "max": mean + 1}}, tree, 3)
    assert check(pose, {"no_background": True}, tree, 3)
    up = pose.copy()
    up[:3, :3] = np.diag([1.0, -1.0, -1.0])  # looking up: nothing hit
    assert not check(up, {"no_background": True}, tree, 3)
    assert check(up, {}, tree, 3)


def test_point_inside_camera_frustum(bproc) -> None:  # noqa: F811
    _camera_at(bproc, 5.0)
    assert bproc.camera.is_point_inside_camera_frustum([0, 0, 0])
    assert not bproc.camera.is_point_inside_camera_frustum([0, 0, 6])  # behind the camera
    assert not bproc.camera.is_point_inside_camera_frustum([0, 0, 4.95])  # nearer than clip_start 0.1
    fx = bproc.camera.get_intrinsics_as_K_matrix()[0, 0]
    edge_x = 5.0 * 16 / fx  # the image's right edge 5 m below the camera
    assert bproc.camera.is_point_inside_camera_frustum([edge_x * 0.99, 0, 0])
    assert not bproc.camera.is_point_inside_camera_frustum([edge_x * 1.01, 0, 0])


def test_lens_distortion_mapping_distorts_back_onto_every_pixel(bproc) -> None:  # noqa: F811
    K = np.array([[30.0, 0, 16.2], [0, 30.0, 11.4], [0, 0, 1]])
    bproc.camera.set_intrinsics_from_K_matrix(K, 32, 24)
    k1, k2, k3, p1, p2 = -0.172992, 0.0248708, 0.00149384, 0.000311976, -9.62967e-5
    mapping = bproc.camera.set_lens_distortion(k1, k2, k3, p1, p2)
    render_K = bproc.camera.get_intrinsics_as_K_matrix()
    width, height = bproc.camera.SESSION.camera.blender.resolution_x, bproc.camera.SESSION.camera.blender.resolution_y
    assert mapping.shape == (2, 32 * 24)
    assert render_K[0, 0] == pytest.approx(30.0) and render_K[1, 1] == pytest.approx(30.0)
    # the mapped points, undistorted, distort onto the pixel grid of the wanted image (within 0.15 px)
    x = (mapping[1] - render_K[0, 2]) / 30.0
    y = (mapping[0] - render_K[1, 2]) / 30.0
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 ** 2 + k3 * r2 ** 3
    u = 30.0 * (x * radial + 2 * p2 * x * y + p1 * (r2 + 2 * x * x)) + 16.2
    v = 30.0 * (y * radial + 2 * p1 * x * y + p2 * (r2 + 2 * y * y)) + 11.4
    rows, cols = np.divmod(np.arange(32 * 24), 32)
    assert np.max(np.hypot(u - cols, v - rows)) <= 0.15
    # the render covers every mapped point with one pixel to spare on each side
    assert mapping[1].min() >= 1 and mapping[1].max() <= width - 2
    assert mapping[0].min() >= 1 and mapping[0].max() <= height - 2
    assert np.floor(mapping[1].min()) == 1 and np.floor(mapping[0].min()) == 1
    # barrel distortion (k1 < 0): the render is larger than the image
    assert width > 32 and height > 24
    image = np.broadcast_to(np.arange(width, dtype=np.float32)[None, :], (height, width))  # value = column
    distorted = bproc.postprocessing.apply_lens_distortion(image, mapping, 32, 24)
    assert np.allclose(distorted.ravel(), mapping[1], atol=0.05)  # a quadratic spline of a ramp (edges: ~0.01)


def test_depth_of_field_is_blenders_thin_lens_focused_on_its_object(bproc) -> None:  # noqa: F811
    from hybridgen.bproc import render_frames
    from hybridgen.bproc.session import SESSION, current_intrinsics

    focus = bproc.object.create_empty("Focus")
    focus.set_location([0, 0, 1], frame=0)
    focus.set_location([0, 0, -2], frame=1)
    bproc.camera.add_depth_of_field(focus, fstop_value=0.25)
    _camera_at(bproc, 4.0)
    _camera_at(bproc, 4.0)
    dof0, dof1 = render_frames._depth_of_field(0), render_frames._depth_of_field(1)
    lens_m = SESSION.camera.blender.lens * 1e-3  # Blender: aperture radius = lens / (2 f-stop)
    assert dof0.aperture_radius(current_intrinsics()) == pytest.approx(lens_m / 0.5)
    pose = np.diag([1.0, -1.0, -1.0, 1.0])
    pose[2, 3] = 4.0  # the OpenCV-axes pose of both frames
    assert dof0.distance_at(pose) == pytest.approx(3.0) and dof1.distance_at(pose) == pytest.approx(6.0)
    assert len(render_frames._groups([0, 1])) == 2  # the focus moves: the frames render apart
    # circle of confusion of a point 1 m behind the focus plane: 2 fx R |z - s| / (z s)
    fx = current_intrinsics().K[0, 0]
    assert dof0.blur_diameter_px(current_intrinsics(), 4.0, 3.0) == pytest.approx(2 * fx * lens_m / 0.5 / 12)
    bproc.camera.add_depth_of_field(None, fstop_value=2.0, focal_distance=1.5)
    assert render_frames._depth_of_field(0).distance_at(pose) == pytest.approx(1.5)
    with pytest.raises(Exception, match="aperture_blades"):
        bproc.camera.add_depth_of_field(focus, 1.0, aperture_blades=6)


def test_camera_frustum_corners_and_object(bproc) -> None:  # noqa: F811
    bproc.camera.set_resolution(640, 480)
    pose = bproc.math.build_transformation_mat([1.0, -2.0, 3.0], [0.4, -0.2, 1.1])
    bproc.camera.add_camera_pose(pose)
    corners = bproc.camera.get_camera_frustum(clip_start=0.5, clip_end=4.0)
    # BlenderProc's path: NDC corners through the inverse of the perspective matrix built from the fov
    fov_x, fov_y = bproc.camera.get_fov()
    near, far = 0.5, 4.0
    projection = np.array([[1 / math.tan(fov_x / 2), 0, 0, 0], [0, 1 / math.tan(fov_y / 2), 0, 0],
                           [0, 0, -(near + far) / (far - near), -2 * near * far / (far - near)], [0, 0, -1, 0]])
    ndc = np.array([[x, y, z, 1.0] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    local = ndc @ np.linalg.inv(projection).T
    expected = (local / local[:, 3:]) @ pose.T
    np.testing.assert_allclose(corners, expected[:, :3], atol=1e-9)
    frustum = bproc.camera.get_camera_frustum_as_object(clip_start=near, clip_end=far)
    assert frustum.get_name() == "Camera Frustum"
    vertices, faces = frustum.world_triangles()
    # the cube's 8 corners (hybridgen splits them where the UV map has seams)
    assert sorted(set(map(tuple, np.round(vertices, 9)))) == sorted(map(tuple, np.round(corners, 9)))
    # a closed truncated pyramid of volume (h / 3) (A1 + A2 + sqrt(A1 A2)); the cube's +z corners go to the far
    # plane, along the camera's -z, a mirroring: its faces wind inwards, as in Blender (negative signed volume)
    tri = vertices[faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    areas = [4 * d * d * math.tan(fov_x / 2) * math.tan(fov_y / 2) for d in (near, far)]
    assert -volume == pytest.approx((far - near) / 3 * (areas[0] + areas[1] + math.sqrt(areas[0] * areas[1])))
