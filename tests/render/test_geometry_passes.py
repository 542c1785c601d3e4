"""Optical flow and NOCS against analytic values."""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.io.memory_sink import MemorySink


def _plane_scene(depth: float, shift: float, with_box: bool) -> hg.Scene:
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 200.0, name="wall", category_id=1))  # z = 0, facing +Z
    if with_box:
        scene.add(hg.make_primitive("cube", 0.4, name="box", category_id=2, local2world=hg.object_pose([0, 0, 1.0])))
    scene.camera.intrinsics = hg.Intrinsics(np.array([[60.0, 0, 31.5], [0, 60.0, 23.5], [0, 0, 1]]), 64, 48)
    for x in (0.0, shift):
        pose = np.eye(4)
        pose[:3, :3] = np.diag([1.0, -1.0, -1.0])  # looking down -Z; camera x = world x
        pose[:3, 3] = [x, 0, depth]
        scene.camera.add_keypoint(pose)
    return scene


def _render(scene: hg.Scene, **request) -> list[dict]:
    sink = MemorySink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"], **request))
    return sink.frames


def test_pure_translation_against_a_plane_gives_analytic_flow(gl_context):
    depth, shift = 4.0, 0.55
    frames = _render(_plane_scene(depth, shift, with_box=False), flow=True)
    expected = 60.0 * shift / depth  # the scene moves left by fx * tx / z pixels
    first, second = frames
    visible = first["forward_flow_occluded"] == 0
    np.testing.assert_allclose(first["forward_flow"][..., 0][visible], -expected, atol=1e-4)
    np.testing.assert_allclose(first["forward_flow"][..., 1][visible], 0.0, atol=1e-4)
    # points that leave the next image are flagged: columns u - 8.25 < -0.5, i.e. u <= 7, leave it
    columns = np.flatnonzero(~visible.all(axis=0))
    np.testing.assert_array_equal(columns, np.arange(0, 8))
    np.testing.assert_allclose(second["backward_flow"][..., 0][second["backward_flow_occluded"] == 0], expected,
                               atol=1e-4)
    assert (second["forward_flow_occluded"] == 1).all() and (second["forward_flow"] == 0).all()  # no keypoint 2
    assert (first["backward_flow_occluded"] == 1).all()


def test_occluded_points_are_flagged(gl_context):
    depth, shift = 4.0, 1.0
    frames = _render(_plane_scene(depth, shift, with_box=True), flow=True)
    first = frames[0]
    ids = first["instance_segmaps"]
    wall_flagged = (first["forward_flow_occluded"] == 1) & (ids == 1)
    # the wall points that the box hides in keypoint 1: project them and check by ray against the box
    v, u = np.mgrid[0:48, 0:64]
    x_world = (u - 31.5) / 60.0 * depth  # wall point under pixel (camera at x = 0, looking down)
    y_world = -(v - 23.5) / 60.0 * depth
    # seen from (shift, 0, depth), the ray to (x, y, 0) crosses z = 1.2 (box top) at:
    t = (depth - 1.2) / depth
    cx, cy = shift + t * (x_world - shift), t * y_world
    hidden = (np.abs(cx) <= 0.2) & (np.abs(cy) <= 0.2)
    u_next = (x_world - shift) / depth * 60.0 + 31.5
    inside = (u_next > -0.5) & (u_next < 63.5)
    expected = (ids == 1) & (hidden | ~inside)
    # allow disagreement only on pixels adjacent to the hidden region's edge (nearest-pixel depth lookup)
    edge = np.zeros_like(expected)
    edge[1:-1, 1:-1] = (expected[1:-1, 1:-1] != expected[:-2, 1:-1]) | (expected[1:-1, 1:-1] != expected[2:, 1:-1]) \
        | (expected[1:-1, 1:-1] != expected[1:-1, :-2]) | (expected[1:-1, 1:-1] != expected[1:-1, 2:])
    assert (hidden & (ids == 1)).sum() > 20
    assert ((wall_flagged != expected) & ~edge).sum() == 0


def test_nocs_of_a_cube(gl_context):
    scene = hg.Scene()
    size = 0.6
    scene.add(hg.make_primitive("cube", size, name="c", category_id=1,
                                local2world=hg.object_pose([1, 2, 0.5], [0.2, 0.1, 0.7], 1.5)))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.7, 64, 48)
    scene.camera.add_keypoint(hg.look_at([3, 0, 2.5], [1, 2, 0.5]))
    frame = _render(scene, nocs=True, depth=True)[0]
    hit = frame["instance_segmaps"] == 1
    values = frame["nocs"][hit]
    diagonal = size * np.sqrt(3)
    low, high = 0.5 - size / 2 / diagonal, 0.5 + size / 2 / diagonal
    assert values.min() >= low - 1e-4 and values.max() <= high + 1e-4
    # every visible point lies on a face: one coordinate sits at a box bound
    on_face = (np.abs(values - low) < 1e-4) | (np.abs(values - high) < 1e-4)
    assert on_face.any(axis=1).all()
    assert (frame["nocs"][~hit] == 0).all()


def test_object_records_poses_boxes_and_visible_fractions(gl_context):
    """A cube half hidden behind a wall: amodal box from drawing it alone, visible fraction about 1/2."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=3, local2world=hg.object_pose([0, 0, 0])))
    wall = hg.MeshObject("wall", [[0, -5, -5], [10, -5, -5], [10, -5, 5], [0, -5, 5]], [[0, 1, 2], [0, 2, 3]],
                         category_id=1)
    scene.add(wall)
    wall.local2world = hg.object_pose([0, 4.0, 0])  # the wall plane y = -1 covers x >= 0
    scene.camera.intrinsics = hg.Intrinsics(np.array([[40.0, 0, 31.5], [0, 40.0, 23.5], [0, 0, 1]]), 64, 48)
    pose = hg.look_at([0, -6, 0], [0, 0, 0])
    scene.camera.add_keypoint(pose)
    frame = _render(scene, object_records=True)[0]
    records = {r["name"]: r for r in frame["object_records"]}
    cube = records["cube"]
    obj2cam = np.array(cube["obj2cam"])
    np.testing.assert_allclose(obj2cam, np.linalg.inv(pose) @ scene.objects[0].local2world, atol=1e-12)
    np.testing.assert_allclose(obj2cam[:3, 3], [0, 0, 6], atol=1e-12)  # 6 m straight ahead
    # the cube's front face (y = -0.5, depth 5.5) spans u, v in 31.5 -+ 40 * 0.5 / 5.5 = 27.86..35.14
    assert cube["bbox_obj"] == [28, 20, 8, 8]
    assert cube["bbox_visib"][0] == 28 and cube["bbox_visib"][2] == 4  # the right half (x >= 0) is hidden
    assert cube["px_count_all"] == 64 and cube["px_count_visib"] == 32 and cube["visib_fract"] == 0.5
    corners = np.array(cube["bbox3d_cam"])
    np.testing.assert_allclose(corners[:, 2].min(), 5.5) and np.testing.assert_allclose(corners[:, 2].max(), 6.5)
    assert records["wall"]["visib_fract"] == 1.0


def test_flow_follows_an_object_moved_between_keypoints(gl_context):
    """Fixed camera 4 m above the floor, looking down; a 0.4 m cube (top face at z = 0.4) moves by (0.5, 0.2)
    between keypoints 0 and 1 (ObjectKeyframes, as composite.CameraObjectSampler records them). On the top
    face the flow is the projected displacement f * d / (4 - 0.4) (camera x = world x, camera y = -world y);
    on the floor it is 0, and the floor the cube covers at keypoint 1 is flagged occluded."""
    from hybridgen.scene.object_keyframes import ObjectKeyframes

    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 200.0, name="floor", category_id=1))
    cube = scene.add(hg.make_primitive("cube", 0.4, name="box", category_id=2,
                                       local2world=hg.object_pose([-0.3, 0.1, 0.2])))
    focal, height = 60.0, 4.0
    scene.camera.intrinsics = hg.Intrinsics(np.array([[focal, 0, 31.5], [0, focal, 23.5], [0, 0, 1]]), 64, 48)
    camera = np.diag([1.0, -1.0, -1.0, 1.0])
    camera[:3, 3] = [0, 0, height]
    keyframes = ObjectKeyframes()
    shift = np.array([0.5, 0.2, 0.0])
    for place in ([-0.3, 0.1, 0.2], [-0.3 + shift[0], 0.1 + shift[1], 0.2]):
        cube.local2world = hg.object_pose(place)
        keyframes.record(scene)
        scene.camera.add_keypoint(camera)
    scene.object_keyframes = keyframes
    first, second = _render(scene, flow=True, depth=True)
    expected = focal * np.array([shift[0], -shift[1]]) / (height - 0.4)  # (u, v) px
    for frame, key, sign in ((first, "forward", 1.0), (second, "backward", -1.0)):
        top = (frame["instance_segmaps"] == cube.instance_id) & np.isclose(frame["depth"], height - 0.4, atol=1e-4)
        assert top.sum() > 20
        np.testing.assert_allclose(frame[f"{key}_flow"][top], np.broadcast_to(sign * expected, (top.sum(), 2)),
                                   atol=1e-3)
        assert (frame[f"{key}_flow_occluded"][top] == 0).all()  # the top face is seen where it moved to
        floor = frame["instance_segmaps"] == 1
        np.testing.assert_allclose(frame[f"{key}_flow"][floor], 0.0, atol=1e-4)  # static: camera motion only
        # the floor is hidden in the other keypoint exactly where the cube stands there
        other = second if key == "forward" else first
        covered = other["instance_segmaps"] == cube.instance_id
        np.testing.assert_array_equal(frame[f"{key}_flow_occluded"][floor], covered[floor].astype(np.uint8))


def test_flow_to_a_keypoint_with_other_intrinsics_zooms(gl_context):
    """Fixed camera over a plane, keypoint 1 with twice the focal length (per-keypoint intrinsics, as BOP scene
    replication sets them): the point at pixel u of keypoint 0 lands at c + 2 (u - c), so forward flow is
    (u - c, v - c_y) where it stays in the image, and the rest is flagged as leaving it."""
    scene = _plane_scene(4.0, 0.0, with_box=False)
    first_k = scene.camera.intrinsics.K
    zoomed = first_k.copy()
    zoomed[0, 0] = zoomed[1, 1] = 2 * first_k[0, 0]
    scene.camera.intrinsics_per_keypoint = [scene.camera.intrinsics, hg.Intrinsics(zoomed, 64, 48)]
    first, second = _render(scene, flow=True)
    v, u = np.mgrid[0:48, 0:64]
    expected = np.stack([u - 31.5, v - 23.5], axis=-1)
    stays = (np.abs(2 * (u - 31.5)) < 32) & (np.abs(2 * (v - 23.5)) < 24)
    np.testing.assert_allclose(first["forward_flow"][stays], expected[stays], atol=1e-3)
    np.testing.assert_array_equal(first["forward_flow_occluded"], (~stays).astype(np.uint8))
    np.testing.assert_allclose(second["backward_flow"], -expected / 2, atol=1e-3)  # zooming out: all visible
    assert (second["backward_flow_occluded"] == 0).all()
