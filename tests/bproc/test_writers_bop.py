"""bproc.writer.write_bop on a tiny scene built through the bproc API: a 0.4 m cube (category 3) under a small
occluding cube, seen from 2 m straight above and from a yawed camera. Files and layout, poses against matrices
computed by hand (OpenCV camera axes, mm), camera.json against the default field of view, depth PNG values
(mm / depth_scale, saturated background), masks against the instance segmap, scene_gt_info counts, the chunk's
COCO file through pycocotools, and appending over two calls as BlenderProc's render-write-reset loops do."""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import InputError

from writer_session import bproc  # noqa: F401 - the fixture

YAW = 0.3  # rad, the cube's and the second camera's rotation about world z
CUBE_AT = np.array([0.1, 0.05, 0.2])  # cube centre (m); its top face at z = 0.4
OPENCV_FROM_BLENDER = np.diag([1.0, -1.0, -1.0])  # camera axes: Blender (y up, -z forward) -> OpenCV


def rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


CAMERAS = [(np.eye(3), np.array([0.0, 0.0, 2.0])), (rz(YAW), np.array([0.2, 0.0, 2.5]))]  # Blender rotation, location


def render(bproc: Any, cameras: list[tuple[np.ndarray, np.ndarray]] = CAMERAS) -> tuple[Any, dict[str, list]]:
    """The cube (instance 1), the occluder (instance 2) and one frame per camera; labels only."""
    cube = bproc.object.create_primitive("CUBE", size=0.4, location=CUBE_AT, rotation=[0, 0, YAW])
    cube.set_cp("category_id", 3)
    occluder = bproc.object.create_primitive("CUBE", size=0.1, location=[0.1, 0.05, 0.8])
    occluder.set_cp("category_id", 5)
    for rotation, location in cameras:
        bproc.camera.add_camera_pose(bproc.math.build_transformation_mat(location, rotation))
    bproc.renderer.enable_depth_output(activate_antialiasing=False)
    bproc.renderer.enable_segmentation_output(map_by=["instance", "category_id"])
    return cube, bproc.renderer.render(output_key=None)


def colors(count: int, shift: int = 0) -> list[np.ndarray]:
    ramp = np.arange(32, dtype=np.uint8)[None, :, None] * 7
    return [np.broadcast_to(ramp + np.array([f + shift, 40, 90], np.uint8), (24, 32, 3)).copy() for f in range(count)]


def load(path: Path) -> Any:
    return json.loads(path.read_text())


def png(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path))


def expected_pose(frame: int) -> tuple[np.ndarray, np.ndarray]:
    """(R 3x3, t mm) of the cube in camera ``frame``'s OpenCV axes, by hand: R_w2c = F R_cam^T (F flips y, z)."""
    rotation, location = CAMERAS[frame]
    w2c = OPENCV_FROM_BLENDER @ rotation.T
    return w2c @ rz(YAW), 1000.0 * w2c @ (CUBE_AT - location)


def test_bop_files_poses_depth_and_masks(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    cube, data = render(bproc)
    out = tmp_path / "bop_data"
    bproc.writer.write_bop(str(out), target_objects=[cube], depths=data["depth"], colors=colors(2), dataset="lm",
                           depth_scale=0.1)
    root, chunk = out / "lm", out / "lm" / "train_pbr" / "000000"
    names = ["rgb/000000.png", "rgb/000001.png", "depth/000000.png", "depth/000001.png", "mask/000000_000000.png",
             "mask/000001_000000.png", "mask_visib/000000_000000.png", "mask_visib/000001_000000.png",
             "scene_camera.json", "scene_gt.json", "scene_gt_info.json", "scene_gt_coco.json"]
    assert sorted(str(p.relative_to(chunk)) for p in chunk.rglob("*") if p.is_file()) == sorted(names)
    assert sorted(p.name for p in root.iterdir()) == ["camera.json", "train_pbr"]

    fx = 16 / math.tan(0.691111 / 2)  # BlenderProc's default horizontal fov over 32 px
    camera = load(root / "camera.json")
    assert camera == pytest.approx({"cx": 15.5, "cy": 11.5, "depth_scale": 0.1, "fx": fx, "fy": fx, "height": 24,
                                    "width": 32}, rel=1e-6)
    assert isinstance(camera["width"], int) and isinstance(camera["height"], int)

    gt, cams = load(chunk / "scene_gt.json"), load(chunk / "scene_camera.json")
    assert sorted(gt) == sorted(cams) == ["0", "1"]
    for frame in (0, 1):
        (entry,) = gt[str(frame)]
        rotation, translation = expected_pose(frame)
        assert entry["obj_id"] == 3 and isinstance(entry["obj_id"], int)
        assert len(entry["cam_R_m2c"]) == 9 and all(isinstance(v, float) for v in entry["cam_R_m2c"])
        np.testing.assert_allclose(entry["cam_R_m2c"], rotation.ravel(), atol=1e-9)  # row-major
        np.testing.assert_allclose(entry["cam_t_m2c"], translation, atol=1e-6)
        w2c_rotation = OPENCV_FROM_BLENDER @ CAMERAS[frame][0].T
        np.testing.assert_allclose(cams[str(frame)]["cam_K"], [fx, 0, 15.5, 0, fx, 11.5, 0, 0, 1], rtol=1e-6)
        np.testing.assert_allclose(cams[str(frame)]["cam_R_w2c"], w2c_rotation.ravel(), atol=1e-9)
        np.testing.assert_allclose(cams[str(frame)]["cam_t_w2c"], -1000 * w2c_rotation @ CAMERAS[frame][1], atol=1e-6)
        assert cams[str(frame)]["depth_scale"] == 0.1
    np.testing.assert_allclose(gt["1"][0]["cam_R_m2c"], [1, 0, 0, 0, -1, 0, 0, 0, -1], atol=1e-9)  # same yaw
    np.testing.assert_allclose(gt["0"][0]["cam_t_m2c"], [100, -50, 1800], atol=1e-6)

    for frame in (0, 1):
        assert np.array_equal(png(chunk / f"rgb/{frame:06d}.png"), colors(2)[frame])
        depth = png(chunk / f"depth/{frame:06d}.png")
        assert Image.open(chunk / f"depth/{frame:06d}.png").mode == "I;16"
        expected = np.minimum(np.rint(np.asarray(data["depth"][frame], np.float64) * 1000 / 0.1), 65535)
        assert np.array_equal(depth, expected)
        instances = np.asarray(data["instance_segmaps"][frame])
        visible, occluder = instances == 1, instances == 2
        assert np.array_equal(png(chunk / f"mask_visib/{frame:06d}_000000.png"), visible * 255)
        full = png(chunk / f"mask/{frame:06d}_000000.png") == 255
        assert np.array_equal(full, visible | occluder)  # the occluder lies inside the cube's silhouette
        assert occluder.any() and visible.any()
        assert np.all(depth[~(visible | occluder)] == 65535)  # Cycles' 1e10 background saturates
    top = png(chunk / "depth/000000.png")[png(chunk / "mask_visib/000000_000000.png") == 255]
    assert np.all(top == 16000)  # the top face 1.6 m below the camera, in units of 0.1 mm

    info = load(chunk / "scene_gt_info.json")["0"][0]
    instances = np.asarray(data["instance_segmaps"][0])
    visible, full = instances == 1, instances > 0
    ys, xs = np.nonzero(visible)
    fys, fxs = np.nonzero(full)
    assert info == {"bbox_obj": [fxs.min(), fys.min(), fxs.max() - fxs.min(), fys.max() - fys.min()],
                    "bbox_visib": [xs.min(), ys.min(), xs.max() - xs.min(), ys.max() - ys.min()],
                    "px_count_all": int(full.sum()), "px_count_valid": int(full.sum()),
                    "px_count_visib": int(visible.sum()), "visib_fract": pytest.approx(visible.sum() / full.sum())}

    coco_api = pytest.importorskip("pycocotools.coco").COCO(str(chunk / "scene_gt_coco.json"))
    assert [c["id"] for c in coco_api.loadCats(coco_api.getCatIds())] == [3]
    assert coco_api.loadCats(3)[0]["supercategory"] == "lm"
    for frame in (0, 1):
        (ann,) = coco_api.loadAnns(coco_api.getAnnIds(imgIds=frame))
        visible = np.asarray(data["instance_segmaps"][frame]) == 1
        assert np.array_equal(coco_api.annToMask(ann).astype(bool), visible)
        assert coco_api.loadImgs(frame)[0]["file_name"] == f"rgb/{frame:06d}.png"
        fys, fxs = np.nonzero(np.asarray(data["instance_segmaps"][frame]) > 0)
        assert ann["bbox"] == [fxs.min(), fys.min(), fxs.max() - fxs.min() + 1, fys.max() - fys.min() + 1]


def test_bop_appends_in_chunks_over_render_write_reset_loops(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    out = tmp_path / "bop_data"
    _, data = render(bproc)
    bproc.writer.write_bop(str(out), depths=data["depth"], colors=colors(2), frames_per_chunk=3,
                           calc_mask_info_coco=True)
    bproc.utility.reset_keyframes()
    for rotation, location in CAMERAS:
        bproc.camera.add_camera_pose(bproc.math.build_transformation_mat(location, rotation))
    second = bproc.renderer.render(output_key=None)
    bproc.writer.write_bop(str(out), depths=second["depth"], colors=colors(2, shift=100), frames_per_chunk=3)
    chunks = out / "train_pbr"
    assert sorted(p.name for p in chunks.iterdir()) == ["000000", "000001"]
    first_gt, next_gt = load(chunks / "000000/scene_gt.json"), load(chunks / "000001/scene_gt.json")
    assert sorted(first_gt) == ["0", "1", "2"] and sorted(next_gt) == ["0"]
    assert [e["obj_id"] for e in first_gt["2"]] == [3, 5]  # every visible mesh object, in creation order
    assert sorted(p.name for p in (chunks / "000000/rgb").iterdir()) == ["000000.png", "000001.png", "000002.png"]
    assert np.array_equal(png(chunks / "000000/rgb/000002.png"), colors(2, shift=100)[0])
    assert np.array_equal(png(chunks / "000001/rgb/000000.png"), colors(2, shift=100)[1])
    assert sorted(load(chunks / "000000/scene_gt_info.json")) == ["0", "1", "2"]
    coco = load(chunks / "000000/scene_gt_coco.json")
    assert [image["id"] for image in coco["images"]] == [0, 1, 2]
    assert [a["id"] for a in coco["annotations"]] == list(range(1, 7))  # cube and occluder per image
    assert [a["image_id"] for a in coco["annotations"]] == [0, 0, 1, 1, 2, 2]
    assert [a["id"] for a in load(chunks / "000001/scene_gt_coco.json")["annotations"]] == [1, 2]
    assert out.name == "bop_data" and load(chunks / "000000/scene_gt_coco.json")["categories"][0]["supercategory"] \
        == "bop_data"  # no dataset: the folder's name, as BlenderProc's path split gives it

    with pytest.raises(InputError, match="already exists"):
        bproc.writer.write_bop(str(out), depths=second["depth"], colors=colors(2), append_to_existing_output=False)


def test_bop_units_distance_threshold_and_one_line_errors(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    cube, data = render(bproc, CAMERAS[:1])
    bproc.writer.write_bop(str(tmp_path / "m"), [cube], data["depth"], colors(1), annotation_unit="m",
                           save_world2cam=False, calc_mask_info_coco=False)
    chunk = tmp_path / "m" / "train_pbr" / "000000"
    np.testing.assert_allclose(load(chunk / "scene_gt.json")["0"][0]["cam_t_m2c"], [0.1, -0.05, 1.8], atol=1e-9)
    assert sorted(load(chunk / "scene_camera.json")["0"]) == ["cam_K", "depth_scale"]
    assert not (chunk / "mask").exists() and not (chunk / "scene_gt_info.json").exists()
    with pytest.warns(DeprecationWarning, match="m2mm"):
        bproc.writer.write_bop(str(tmp_path / "mm"), [cube], data["depth"], colors(1), m2mm=False,
                               annotation_unit="m")
    assert load(tmp_path / "mm/train_pbr/000000/scene_gt.json")["0"][0]["cam_t_m2c"][2] == pytest.approx(1800)
    bproc.writer.write_bop(str(tmp_path / "near"), None, data["depth"], colors(1), ignore_dist_thres=1.5)
    assert [e["obj_id"] for e in load(tmp_path / "near/train_pbr/000000/scene_gt.json")["0"]] == [5]  # 1.2 m away

    with pytest.raises(InputError, match=r"colors \(2\) does not correspond .* frame_end \(1\)"):
        bproc.writer.write_bop(str(tmp_path / "x"), None, data["depth"], colors(2))
    with pytest.raises(InputError, match="any object from the specified dataset: ycbv"):
        bproc.writer.write_bop(str(tmp_path / "x"), None, data["depth"], colors(1), dataset="ycbv")
    cube.del_cp("category_id")
    with pytest.raises(InputError, match="Cube object has no custom property 'category_id'"):
        bproc.writer.write_bop(str(tmp_path / "x"), [cube], data["depth"], colors(1))
    assert not (tmp_path / "x").exists()  # nothing written by a call that failed


def test_bop_poses_and_masks_follow_keyed_object_poses(gl_context, bproc, tmp_path: Path) -> None:  # noqa: F811
    cube, data = render(bproc, [CAMERAS[0], CAMERAS[0]])  # one camera, two frames
    bproc.utility.reset_keyframes()
    bproc.camera.add_camera_pose(bproc.math.build_transformation_mat(*CAMERAS[0][::-1]), frame=0)
    bproc.camera.add_camera_pose(bproc.math.build_transformation_mat(*CAMERAS[0][::-1]), frame=1)
    cube.set_location(CUBE_AT, frame=0)
    cube.set_location(CUBE_AT + [0.25, 0.0, 0.0], frame=1)  # moved 0.25 m along world x (camera x) in frame 1
    moved = bproc.renderer.render(output_key=None)
    bproc.writer.write_bop(str(tmp_path), [cube], moved["depth"], colors(2))
    chunk = tmp_path / "train_pbr" / "000000"
    gt = load(chunk / "scene_gt.json")
    np.testing.assert_allclose(gt["0"][0]["cam_t_m2c"], [100, -50, 1800], atol=1e-6)
    np.testing.assert_allclose(gt["1"][0]["cam_t_m2c"], [350, -50, 1800], atol=1e-6)
    for frame in (0, 1):
        visible = np.asarray(moved["instance_segmaps"][frame]) == 1
        assert np.array_equal(png(chunk / f"mask_visib/{frame:06d}_000000.png"), visible * 255)
    assert not np.array_equal(moved["instance_segmaps"][0], moved["instance_segmaps"][1])
