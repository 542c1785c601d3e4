"""The one sink protocol (begin/write/end/finalize -> list[Path]/abort), typed pass layouts, writer options
declared once, the shared COCO assembly, and the BOP writer fed by hand-made render-side passes (no GL)."""
from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.config.options import checked_options, from_config, option_params
from hybridgen.io.bop_writer import BopOptions, BopWriter
from hybridgen.io.coco_content import annotation, coco_file
from hybridgen.io.coco_writer import CocoOptions, CocoWriter
from hybridgen.io.frame_sink import PassLayout
from hybridgen.io.hdf5_single import Hdf5Options
from hybridgen.io.renamed_sink import RenamedSink


def test_image_size_of_mono_stereo_and_json_layouts():
    assert PassLayout("depth", "float32", (4, 5)).image_size == (4, 5)
    assert PassLayout("normals", "float32", (4, 5, 3)).image_size == (4, 5)
    assert PassLayout("colors", "uint8", (2, 4, 5, 3), stereo=True).image_size == (4, 5)
    assert PassLayout("depth", "float32", (2, 4, 5), stereo=True).image_size == (4, 5)
    assert PassLayout("instance_attribute_maps", "json", ()).image_size is None


def test_every_writer_finalizes_to_a_list_of_paths(tmp_path):
    depth = PassLayout("depth", "float32", (2, 3), units="m", background=float("inf"))
    hdf5 = hg.Hdf5SingleFileWriter(tmp_path / "a.hdf5")
    memory = hg.MemorySink()
    renamed = RenamedSink(hg.MemorySink(), {"depth": "z"})
    for sink in (hdf5, memory, renamed):
        sink.begin(1, [depth], {}, {"seed": 1})
        sink.write(0, {"depth": np.ones((2, 3), np.float32)})
        sink.end()
    assert hdf5.finalize({"object_states": []}) == [tmp_path / "a.hdf5"]
    assert memory.finalize({"object_states": []}, {"seed": 2}) == []
    assert memory.records["object_states"] == [] and memory.attributes["seed"] == 2
    assert renamed.finalize() == [] and renamed.sink.layouts["z"].background == float("inf")
    coco = CocoWriter(tmp_path / "coco", mask_encoding="polygon")
    coco.begin(1, [PassLayout("colors", "uint8", (2, 3, 3))], {}, {})
    coco.write(0, {"colors": np.zeros((2, 3, 3), np.uint8), "instance_segmaps": np.zeros((2, 3), np.int32),
                   "instance_attribute_maps": []})
    assert coco.finalize() == [tmp_path / "coco/coco_annotations.json"]


def test_stereo_layouts_are_refused_by_dataset_writers(tmp_path):
    writer = CocoWriter(tmp_path, mask_encoding="polygon")
    with pytest.raises(hg.InputError, match="stereo"):
        writer.begin(1, [PassLayout("colors", "uint8", (2, 4, 5, 3), stereo=True)], {}, {})
    writer.abort()


def test_options_are_declared_once_and_checked_once_per_path(tmp_path):
    params = {p.name: p for p in option_params(BopOptions)}
    assert params["append_to_existing_output"].default is False and "append" not in params
    assert params["depth_scale"].unit == "mm" and params["annotation_unit"].choices == ("m", "dm", "cm", "mm")
    assert [p.name for p in option_params(CocoOptions)][:2] == ["rgb_output_key", "mask_encoding_format"]
    config = {p.name: p.default for p in option_params(BopOptions)} | {"depth_scale": 0.1}
    assert from_config(BopOptions, config) == BopOptions(depth_scale=0.1)
    with pytest.raises(hg.ConfigError, match="'depth_scale'.*must be > 0"):
        checked_options(BopOptions, depth_scale=0.0)
    with pytest.raises(hg.ConfigError, match="did you mean 'jpg_quality'"):
        checked_options(BopOptions, jpg_qualty=90)
    with pytest.raises(hg.ConfigError, match="'compression'.*'zstd' is not one of"):
        hg.Hdf5SingleFileWriter(tmp_path / "x.hdf5", compression="zstd")
    with pytest.raises(hg.ConfigError, match="'mask_encoding'"):
        CocoWriter(tmp_path, mask_encoding="bitmap")
    with pytest.raises(TypeError):
        hg.Hdf5SingleFileWriter(tmp_path / "x.hdf5", Hdf5Options(), compression="lzf")


def test_coco_file_continues_ids_and_merges_categories():
    existing = {"info": {"description": "old"}, "licenses": [], "categories": [{"id": 2, "name": "old two"}],
                "images": [{"id": 0}], "annotations": [{"id": 7}, {"id": 3}]}
    new = [annotation(1, 2, 5, [0, 0, 2, 3], {"counts": [0, 5], "size": [3, 2]}, 2, 3),
           annotation(1, 4, 1, [1, 1, 1, 1], [], 2, 3, ignore=True)]
    content = coco_file(existing, {"description": "unused"}, [{"id": 2, "name": "two"}, {"id": 4, "name": "four"}],
                        [{"id": 1}], new)
    assert content["info"] == {"description": "old"}
    assert content["categories"] == [{"id": 2, "name": "old two"}, {"id": 4, "name": "four"}]
    assert [a["id"] for a in content["annotations"]] == [7, 3, 8, 9]
    assert list(content["annotations"][3]) == ["id", "image_id", "category_id", "iscrowd", "area", "bbox",
                                                "segmentation", "width", "height", "ignore"]
    fresh = coco_file(None, {"description": "d"}, [], [], new[:1])
    assert list(fresh) == ["info", "licenses", "categories", "images", "annotations"]
    assert fresh["annotations"][0]["id"] == 1


def test_bop_writer_takes_masks_counts_and_boxes_from_the_passes(tmp_path):
    """No renderer: the per-object passes are made by hand, so the writer provably draws nothing itself."""
    scene = hg.Scene()
    cube = scene.add(hg.make_primitive("cube", 0.5, name="cube", category_id=5,
                                       local2world=hg.make_pose(np.eye(3), [0.0, 0.0, 2.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 4, 3)
    scene.camera.add_keypoint(np.eye(4))
    writer = BopWriter(tmp_path, scene, options=checked_options(BopOptions, depth_scale=0.5))
    assert writer.wanted_passes() == ("amodal_masks", "visible_fractions", "object_boxes")
    layouts = [PassLayout("colors", "uint8", (3, 4, 3)), PassLayout("depth", "float32", (3, 4), background=9.0),
               PassLayout("instance_segmaps", "int32", (3, 4))]
    writer.begin(1, layouts, {"cam_K": scene.camera.intrinsics.K[None], "cam2world": np.eye(4)[None]}, {})
    instance = np.zeros((3, 4), np.int32)
    instance[1, 1:3] = cube.instance_id  # 2 visible pixels
    full = np.zeros((3, 4), bool)
    full[0:2, 1:3] = True  # 4 amodal pixels inside the image (say 6 with those outside)
    depth = np.full((3, 4), 9.0, np.float32)
    depth[0:2, 1] = 2.0  # one column of the full mask has depth: 2 valid pixels
    writer.write(0, {"colors": np.zeros((3, 4, 3), np.uint8), "depth": depth, "instance_segmaps": instance,
                     "amodal_masks": {cube.instance_id: full},
                     "visible_fractions": {cube.instance_id: {"px_count_all": 6, "px_count_visib": 2,
                                                              "visib_fract": 2 / 6}},
                     "object_boxes": {cube.instance_id: {"bbox_obj": [1, -1, 1, 2], "bbox_visib": [1, 1, 1, 0]}}})
    writer.end()
    assert writer.finalize() == [tmp_path]
    chunk = tmp_path / "train_pbr/000000"
    info = json.loads((chunk / "scene_gt_info.json").read_text())["0"]
    assert info == [{"bbox_obj": [1, -1, 1, 2], "bbox_visib": [1, 1, 1, 0], "px_count_all": 6,
                     "px_count_valid": 2, "px_count_visib": 2, "visib_fract": 2 / 6}]
    np.testing.assert_array_equal(np.asarray(Image.open(chunk / "mask/000000_000000.png")), full * 255)
    np.testing.assert_array_equal(np.asarray(Image.open(chunk / "mask_visib/000000_000000.png")),
                                  (instance == cube.instance_id) * 255)
    np.testing.assert_array_equal(np.asarray(Image.open(chunk / "depth/000000.png"))[0:2, 1], [4000, 4000])
    gt = json.loads((chunk / "scene_gt.json").read_text())["0"][0]
    assert gt["obj_id"] == 5 and gt["cam_t_m2c"] == [0.0, 0.0, 2000.0]
    coco = json.loads((chunk / "scene_gt_coco.json").read_text())
    assert coco["annotations"][0]["bbox"] == [1, 0, 2, 2] and coco["annotations"][0]["area"] == 2


def test_on_request_passes_reach_a_memory_sink_through_a_renamed_sink(gl_context):
    scene = hg.Scene()
    cube = scene.add(hg.make_primitive("cube", 1.0, name="cube", category_id=3))
    scene.camera.intrinsics = hg.Intrinsics(np.array([[20.0, 0, 15.5], [0, 20.0, 11.5], [0, 0, 1]]), 32, 24)
    scene.camera.add_keypoint(hg.look_at([0, -6, 0], [0, 0, 0]))
    asking, plain = hg.MemorySink(wanted=["amodal_masks", "visible_fractions"]), hg.MemorySink()
    sinks = [RenamedSink(asking, {"instance_segmaps": "ids"}), plain]
    hg.render_labels(scene, sinks, hg.LabelRequest(map_by=["instance"], depth=False, normals=False))
    frame = asking.frames[0]
    visible = frame["ids"] == cube.instance_id  # nothing hides the cube: amodal = visible
    # front face 5.5 m away, 1 m wide: u, v = 15.5 / 11.5 +- 20 * 0.5 / 5.5 -> pixel centres 14..17 and 10..13
    expected = np.zeros((24, 32), bool)
    expected[10:14, 14:18] = True
    np.testing.assert_array_equal(visible, expected)
    np.testing.assert_array_equal(frame["amodal_masks"][cube.instance_id], visible)
    assert frame["visible_fractions"][cube.instance_id] == {"px_count_all": 16, "px_count_visib": 16,
                                                             "visib_fract": 1.0}
    assert "amodal_masks" not in plain.frames[0] and "object_boxes" not in frame
