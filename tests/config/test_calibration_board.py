"""object.CalibrationboardSampler: every kept board pose shows all corner_coords inside the image (projected
independently here), the scan reaches the image borders, and each pose is its own keypoint in the renders."""
from __future__ import annotations

import json

import numpy as np
import pytest

from hybridgen.errors import InputError
from hybridgen.scene.frames import euler_xyz_to_matrix
from tests.config.test_blenderproc_modules import run_config_text

CORNERS = [[-0.4, -0.3, 0.0], [0.4, -0.3, 0.0], [0.4, 0.3, 0.0], [-0.4, 0.3, 0.0]]
K = [550.0, 0.0, 319.5, 0.0, 400.0, 239.5, 0.0, 0.0, 1.0]
W, H = 640, 480


def _board_obj(path):
    """A thin 1 x 0.8 board in file axes (Blender: x right, z up -> file y up), named Board."""
    lines = ["o Board"] + [f"v {x} {z} {-y}" for x, y, z in
                           [(-0.5, -0.4, 0), (0.5, -0.4, 0), (0.5, 0.4, 0), (-0.5, 0.4, 0)]] + ["f 1 2 3", "f 1 3 4"]
    path.write_text("\n".join(lines) + "\n")
    return path


def _config(tmp_path, rot_sampler, extra=None, modules_after=()):
    modules = [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}, "seed": 4}},
        {"module": "loader.ObjectLoader", "config": {"path": str(_board_obj(tmp_path / "board.obj"))}},
        {"module": "camera.CameraLoader", "config": {
            "cam_poses": [{"location": [0, 0, 0], "rotation_euler": [0, 0, 0]}],
            "intrinsics": {"resolution_x": W, "resolution_y": H, "cam_K": K}}},
        {"module": "object.CalibrationboardSampler", "config": {
            "board_name": "Board", "rot_sampler": rot_sampler, "corner_coords": CORNERS,
            "z_planes": [-1.5, -2.5], "x_min": -2, "x_max": 2, "y_min": -2, "y_max": 2, **(extra or {})}},
        *modules_after]
    return json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": modules})


def _project(points_world):
    # camera at the origin with Blender rotation 0 looks along world -Z, image x = world x, image y = -world y
    x, y, depth = points_world[:, 0], -points_world[:, 1], -points_world[:, 2]
    return np.stack([K[0] * x / depth + K[2], K[4] * y / depth + K[5], depth], axis=1)


def test_every_board_pose_shows_all_corners(tmp_path):
    sampler = {"provider": "sampler.Uniform3d", "max": [-0.5, -0.5, -0.5], "min": [0.5, 0.5, 0.5]}
    context = run_config_text(tmp_path, _config(tmp_path, sampler))
    scene = context.scene
    board = scene.by_name("Board")
    keyframes = scene.object_keyframes
    assert len(scene.camera) == len(keyframes.starts) > 20
    assert all(np.array_equal(k, scene.camera.keypoints[0]) for k in scene.camera.keypoints)  # camera held
    heights, us, vs, turns = set(), [], [], set()
    for index in range(len(scene.camera)):
        pose = keyframes.pose(index, board.instance_id)
        corners = np.asarray(CORNERS) @ pose[:3, :3].T + pose[:3, 3]
        projected = _project(corners)
        assert np.all(projected[:, 2] > 0)
        assert np.all((projected[:, 0] > -0.5) & (projected[:, 0] < W - 0.5))
        assert np.all((projected[:, 1] > -0.5) & (projected[:, 1] < H - 0.5))
        heights.add(round(pose[2, 3], 9))
        us += projected[:, 0].tolist()
        vs += projected[:, 1].tolist()
        turns.add(round(float(pose[0, 1]), 6))
    assert heights == {-1.5, -2.5}
    # the scan (0.1 m steps outside the view, both directions) reaches every border: within two small steps
    # (0.1 m at 1.5 m: 37 px across, 27 px down) of each image edge
    assert min(us) < 74 and max(us) > W - 74 and min(vs) < 54 and max(vs) > H - 54
    assert len(turns) > 10  # a rotation drawn per location


def test_board_scan_is_deterministic_and_rejects_what_cannot_be_seen(tmp_path):
    fixed = [0.0, 0.0, 0.0]
    first = run_config_text(tmp_path, _config(tmp_path, fixed)).scene.object_keyframes
    again = run_config_text(tmp_path, _config(tmp_path, fixed)).scene.object_keyframes
    assert first.starts == again.starts
    assert all(np.array_equal(a[k], b[k]) for a, b in zip(first.poses, again.poses) for k in a)
    # a board larger than the view at every plane: no pose, one line
    huge = [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]]
    with pytest.raises(InputError, match="corner_coords"):
        run_config_text(tmp_path, _config(tmp_path, fixed, {"corner_coords": huge}))
    # behind the camera (z planes above it) nothing is kept either, though the points project mirrored
    with pytest.raises(InputError, match="corner_coords"):
        run_config_text(tmp_path, _config(tmp_path, fixed, {"z_planes": [2.0]}))


def test_each_board_pose_renders_in_its_keypoint(tmp_path):
    # few poses (one z plane, coarse steps) and labels only: the board's instance mask in each keypoint covers
    # exactly where its corners project
    extra = {"z_planes": [-2.0], "small_step_size": 0.6, "big_step_size": 0.6, "x_min": -1, "x_max": 1,
             "y_min": -1, "y_max": 1}
    after = [{"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance"]}},
             {"module": "writer.Hdf5Writer", "config": {}}]
    context = run_config_text(tmp_path, _config(tmp_path, [0.0, 0.0, 0.0], extra, after))
    from tests.blenderproc_files import read_numbered

    paths = [p for p in context.outputs if str(p).endswith(".hdf5")]  # BlenderProc's 0.hdf5, 1.hdf5, ...
    assert [p.name for p in paths] == [f"{i}.hdf5" for i in range(len(paths))]
    masks = read_numbered(paths[0].parent)["instance_segmaps"]
    scene = context.scene
    board = scene.by_name("Board")
    assert len(masks) == len(scene.camera) >= 2
    for index, mask in enumerate(masks):
        pose = scene.object_keyframes.pose(index, board.instance_id)
        rect = np.array([[-0.5, -0.4, 0], [0.5, 0.4, 0]]) @ pose[:3, :3].T + pose[:3, 3]
        (u0, v0, _), (u1, v1, _) = np.sort(_project(rect), axis=0)
        rows, cols = np.nonzero(mask == board.instance_id)
        assert cols.min() == pytest.approx(max(0, np.ceil(u0)), abs=1) and cols.max() == pytest.approx(
            min(W - 1, np.floor(u1)), abs=1)
        assert rows.min() == pytest.approx(max(0, np.ceil(v0)), abs=1) and rows.max() == pytest.approx(
            min(H - 1, np.floor(v1)), abs=1)
    np.testing.assert_allclose(euler_xyz_to_matrix([0, 0, 0]), np.eye(3))


def test_a_config_rendering_without_writer_keeps_its_renders(tmp_path):
    # BlenderProc keeps the renderers' own files when no writer follows (the calibration example):
    # hybridgen writes them into data.hdf5, with a notice
    from hybridgen.config.notices import set_sink

    extra = {"z_planes": [-2.0], "small_step_size": 0.9, "big_step_size": 0.9, "x_min": -1, "x_max": 1,
             "y_min": -1, "y_max": 1}
    after = [{"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance"]}}]
    lines: list[str] = []
    set_sink(lines.append)
    try:
        context = run_config_text(tmp_path, _config(tmp_path, [0.0, 0.0, 0.0], extra, after))
    finally:
        set_sink(None)
    import h5py

    with h5py.File(tmp_path / "out" / "data.hdf5") as f:
        assert len(f["instance_segmaps"]) == len(context.scene.camera) >= 1
    assert any("has no writer" in line and "data.hdf5" in line for line in lines)
