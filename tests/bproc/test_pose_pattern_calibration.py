"""bproc.camera.check_novel_pose, bproc.utility.generate_random_pattern_img and
bproc.camera.set_camera_parameters_from_config_file against the real BlenderProc 2.8 (answers stored by
tools/bproc_pose_pattern_calibration.py from BlenderProc on pip's bpy 4.2 with Blender's mathutils and OpenCV 4.10)
and against hand-computed cases: variances worked out by hand, a calibration file of this test's own in the
DLR-RMC format, the frame change of the extrinsics."""
from __future__ import annotations

import hashlib
import json
import random
from pathlib import Path

import numpy as np
import pytest

from hybridgen.bproc.camera_novelty import check_novel_pose
from hybridgen.bproc.dlr_calibration import parse_calibration_text
from hybridgen.bproc.mathutils_standin import Matrix
from hybridgen.bproc.pattern import CIRCLE_RADIUS_1, draw_dots, generate_random_pattern_img
from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture

TABLE = json.loads((Path(__file__).parent / "data" / "bproc_pose_pattern_calibration.json").read_text())
INPUTS = TABLE["inputs"]


# ------------------------------------------------------------------------------------------- check_novel_pose
def test_check_novel_pose_gives_blenderprocs_answers() -> None:
    singles = [check_novel_pose(np.array(case["candidate"]), [np.array(p) for p in case["existing"]],
                                *case["args"]) for case in INPUTS["singles"]]
    assert singles == TABLE["novelty"]["singles"]
    for args, expected in zip(INPUTS["loops"], TABLE["novelty"]["loops"]):
        kept: list[np.ndarray] = []
        answers = []
        for pose in INPUTS["poses"]:
            answers.append(check_novel_pose(np.array(pose), kept, *args))
            if answers[-1]:
                kept.append(np.array(pose))
        assert answers == expected, args
    # the loops are not all-novel or all-rejected: they test something
    assert all(0 < sum(loop) < len(loop) for loop in TABLE["novelty"]["loops"])


def _turn_z(angle: float, location: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    pose = np.eye(4)
    pose[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    pose[:3, 3] = location
    return pose


def test_check_novel_pose_variance_by_hand() -> None:
    # Euler triples (0, 0, 0.2) and (0, 0, 0.4): variance over all six numbers 0.14 / 6 = 7/300; adding
    # (0, 0, 0.6): 0.4 / 9 = 4/90, an increase of (4/90) / (7/300) - 1 = 90.476 %
    existing = [_turn_z(0.2), _turn_z(0.4)]
    assert check_novel_pose(_turn_z(0.6), existing, True, False, 90.4)
    assert not check_novel_pose(_turn_z(0.6), existing, True, False, 90.5)
    assert len(existing) == 2  # the scratch list is not the caller's
    # a value at the mean lowers the variance: rejected even at the default threshold
    assert not check_novel_pose(_turn_z(0.1), existing, True, False)
    # translations (0, 0, 0) and (0, 0, 2): variance of (0, 0, 0, 0, 0, 2) = 2/3 - 1/9 = 45/81; adding (0, 0, 3):
    # 13/9 - 25/81 = 92/81, an increase of 47/45 = 104.44 %
    moved = [_turn_z(0.0, (0, 0, 0)), _turn_z(0.0, (0, 0, 2))]
    increase = 47 / 45 * 100
    assert check_novel_pose(_turn_z(0.0, (0, 0, 3)), moved, False, True, -1, increase - 1e-6)
    assert not check_novel_pose(_turn_z(0.0, (0, 0, 3)), moved, False, True, -1, increase + 1e-6)
    # the rotation test fails first: a new place does not help
    assert not check_novel_pose(_turn_z(0.1, (5, 5, 5)), existing, True, True)
    assert check_novel_pose(_turn_z(0.1, (5, 5, 5)), existing, False, True)
    # mathutils matrices are poses too
    assert check_novel_pose(Matrix(_turn_z(0.6)), [Matrix(p) for p in existing], True, False, 90.4)


def test_mathutils_standin_to_euler_is_blenders_triple() -> None:
    # Blender 4.2 (pip bpy): Euler((3.0, 0.2, 3.0)).to_matrix().to_euler() is the other triple, whose absolute
    # values sum less: (-0.14159265160560608, 2.9415926933288574, -0.14159266650676727)
    turn = Matrix(np.array(_turn_z(3.0))) @ Matrix(np.array([[np.cos(0.2), 0, np.sin(0.2), 0], [0, 1, 0, 0],
                                                              [-np.sin(0.2), 0, np.cos(0.2), 0], [0, 0, 0, 1]]))
    turn = turn @ Matrix(np.array([[1, 0, 0, 0], [0, np.cos(3.0), -np.sin(3.0), 0], [0, np.sin(3.0), np.cos(3.0), 0],
                                   [0, 0, 0, 1]]))
    np.testing.assert_allclose(np.array(turn.to_euler()), [-0.14159265160560608, 2.9415926933288574,
                                                          -0.14159266650676727], atol=1e-6)


def test_check_novel_pose_first_pose_and_zero_variance() -> None:
    assert check_novel_pose(_turn_z(0.3), [], True, True, 1e9, 1e9)  # the first pose is always novel
    # one existing identity pose: old variance 0, any increase is infinite (0 / 0 too): novel at any threshold
    assert check_novel_pose(_turn_z(0.3, (1, 2, 3)), [np.eye(4)], True, True, 1e9, 1e9)
    assert check_novel_pose(np.eye(4), [np.eye(4)], True, True, 1e9, 1e9)
    # an equal variance passes -1 and 0 percent, not more
    pose = _turn_z(0.7, (0.5, -1.0, 2.0))
    assert check_novel_pose(pose, [pose], False, True, -1, -1)
    assert not check_novel_pose(pose, [pose], False, True, -1, 1e-9)
    with pytest.raises(InputError, match="cam2world_matrix must be a finite 4x4"):
        check_novel_pose(np.eye(2), [np.eye(4)], True, True)


# ------------------------------------------------------------------------------------------------- pattern
def test_opencv_circle_of_radius_one_is_a_plus() -> None:
    """OpenCV 4.10's filled radius-1 circle (stored measurement) is the five-pixel stencil, clipped at borders."""
    for (x, y), measured in zip(INPUTS["circle_centres"], TABLE["circle"]):
        ours = np.argwhere(draw_dots(5, 5, [(x, y)])[..., 3] > 0).tolist()
        assert ours == measured
    assert TABLE["circle"][0] == [[1, 2], [2, 1], [2, 2], [2, 3], [3, 2]]
    assert sorted(CIRCLE_RADIUS_1) == sorted((r - 2, c - 2) for r, c in TABLE["circle"][0])


@pytest.mark.parametrize("case", range(len(INPUTS["patterns"])))
def test_pattern_is_blenderprocs_bytes(case: int) -> None:
    seed, width, height, n_points = INPUTS["patterns"][case]
    expected = TABLE["pattern"][case]
    random.seed(seed)
    image = generate_random_pattern_img(width, height, n_points)
    after = random.random()
    assert list(image.shape) == expected["shape"] == [height, width, 4] and str(image.dtype) == expected["dtype"]
    assert hashlib.sha256(image.tobytes()).hexdigest() == expected["sha256"]
    assert after == expected["next_random"]  # as many draws as BlenderProc
    assert sorted(np.unique(image).tolist()) == expected["values"] == [0, 255]
    if "lit_pixels" in expected:
        assert np.argwhere(image[..., 3] > 0).tolist() == expected["lit_pixels"]


def test_pattern_cells_and_errors() -> None:
    random.seed(3)
    image = generate_random_pattern_img(30, 20, 9)  # cells 10 x 6 px: 3 columns x 3 rows of cells
    assert (image[..., 3] > 0).sum() <= 9 * 5 and (image[..., :3] == image[..., 3:]).all()
    for width, height, n_points in ((4, 30, 25), (30, 30, 0)):
        with pytest.raises(InputError):
            generate_random_pattern_img(width, height, n_points)


# --------------------------------------------------------------------------------------------- calibration
OWN_FILE = """# DLR-RMC camera calibration (hybridgen test values)
version=2
origin=center # a trailing comment
camera.0.A=[ 50 0 20; 0 55 15; 0 0 1]
camera.0.width= 40
camera.0.height= 30
camera.0.k1= 0.5
camera.0.k1= -0.05
camera.0.R=[ 1 0 0; 0 1 0; 0 0 1]
camera.0.T=[ 1.0 2.0 3.0]
camera.2.k1= 0.3
camera.2.A=[10, 0, 5; 0, 10, 5; 0, 0, 1]
camera.2.T=[ 1; 2; 3]
camera.k2= 0.7
camera.rmsInt= 0.1
weird=a=b
"""


def test_parser_reads_one_camera_and_the_file_keys() -> None:
    assert parse_calibration_text(OWN_FILE, 0) == {
        "version": 2, "origin": "center", "A": [[50.0, 0.0, 20.0], [0.0, 55.0, 15.0], [0.0, 0.0, 1.0]],
        "width": 40, "height": 30, "k1": -0.05, "R": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        "T": [1.0, 2.0, 3.0]}
    assert parse_calibration_text(OWN_FILE, 2) == {
        "version": 2, "origin": "center", "k1": 0.3, "A": [[10.0, 0.0, 5.0], [0.0, 10.0, 5.0], [0.0, 0.0, 1.0]],
        "T": [[1.0], [2.0], [3.0]]}


def test_calibration_file_sets_camera_as_blenderproc(bproc, tmp_path) -> None:  # noqa: F811
    path = tmp_path / "calibration.cal"
    path.write_text(INPUTS["calibration_file"])
    for name, (index, extrinsics) in {"camera 1 with extrinsics": (1, True), "camera 0": (0, False)}.items():
        expected = TABLE["calibration"]["runs"][name]
        bproc.utility.reset_keyframes()
        width, height, mapping = bproc.camera.set_camera_parameters_from_config_file(str(path), extrinsics, index)
        camera = bproc.camera.SESSION.camera.blender
        assert [width, height] == expected["returned"]
        assert [camera.resolution_x, camera.resolution_y] == expected["resolution"]
        np.testing.assert_allclose(bproc.camera.get_intrinsics_as_K_matrix(), expected["K"], atol=1e-4)
        assert bproc.utility.num_frames() == expected["frames"]
        for frame, pose in enumerate(expected["poses"]):
            np.testing.assert_allclose(bproc.camera.get_camera_pose(frame), pose, atol=1e-6)  # float32 there
        assert list(mapping.shape) == expected["mapping_shape"]
        # BlenderProc inverts the distortion to 0.15 px, hybridgen more closely: measured 0.013 px apart
        np.testing.assert_allclose(mapping[:, ::97], expected["mapping_every_97th"], atol=0.05)


def test_calibration_extrinsics_frame_change(bproc, tmp_path) -> None:  # noqa: F811
    path = tmp_path / "own.cal"
    path.write_text(OWN_FILE)
    assert bproc.camera.set_camera_parameters_from_config_file(str(path), True)[:2] == (40, 30)
    assert bproc.camera.set_camera_parameters_from_config_file(str(path), True)[:2] == (40, 30)
    # Pw = R Pc + T with Pc in OpenCV axes: the Blender-axes cam2world flips y and z; each call keys a new frame
    expected = np.diag([1.0, -1.0, -1.0, 1.0])
    expected[:3, 3] = [1.0, 2.0, 3.0]
    assert bproc.utility.num_frames() == 2
    np.testing.assert_allclose(bproc.camera.get_camera_pose(1), expected)
    # fx 50, fy 55: the pixel aspect keeps them apart; barrel distortion (k1 < 0) enlarges the render
    K = bproc.camera.get_intrinsics_as_K_matrix()
    assert K[0, 0] == pytest.approx(50.0) and K[1, 1] == pytest.approx(55.0)
    assert bproc.camera.SESSION.camera.blender.resolution_x > 40


@pytest.mark.parametrize("change, message", [
    (("version=2", "version=3"), "only version 2 .* not 3"),
    (("version=2", ""), "version tag is not set"),
    (("origin=center", "origin=corner"), "origin .* has to be set to center"),
    (("camera.0.k1= -0.05", ""), "k1"),  # both k1 lines go
    (("camera.0.A=[ 50 0 20; 0 55 15; 0 0 1]", "camera.0.A=[ 50 0 20 0 55 15 0 0 1]"), "A must be a 3x3"),
    (("camera.0.width= 40", "camera.0.width= 40.5"), "width must be a positive whole number"),
    (("camera.0.height= 30", ""), "has no height"),
    (("camera.0.T=[ 1.0 2.0 3.0]", "camera.0.T=[ 1.0 2.0]"), "T must be a 3-vector"),
    (("camera.0.k1= -0.05", "camera.0.k1= strong"), "k1 must be a number"),
])
def test_calibration_errors_name_file_and_key(bproc, tmp_path, change, message) -> None:  # noqa: F811
    path = tmp_path / "bad.cal"
    text = OWN_FILE.replace("camera.0.k1= 0.5\n", "") if change[0] == "camera.0.k1= -0.05" else OWN_FILE
    path.write_text(text.replace(*change))
    with pytest.raises(InputError, match=message) as error:
        bproc.camera.set_camera_parameters_from_config_file(str(path), True)
    assert str(path) in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(InputError, match="does not exist: .*missing.cal"):
        bproc.camera.set_camera_parameters_from_config_file(str(tmp_path / "missing.cal"))
