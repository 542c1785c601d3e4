"""BOP scene replication renders each image with its own cam_K from scene_camera.json (BlenderProc keyframes the
principal point per frame): the labels of image i are those of a camera with K_i, and the BOP writer records
each image's K."""
from __future__ import annotations

import json

import numpy as np

import hybridgen as hg
from hybridgen.config.config_file import load_config
from hybridgen.run.pipeline import build_modules, execute
from tests.config.test_blenderproc_configs import BOP_REPLICATION_V3, _bop_standin, write


def test_each_replicated_image_renders_with_its_own_cam_k(tmp_path, monkeypatch):
    monkeypatch.delenv("HYBRIDGEN_TEST_SURELY_UNSET", raising=False)
    dataset = _bop_standin(tmp_path)
    cameras_file = dataset / "test" / "000001" / "scene_camera.json"
    cameras = json.loads(cameras_file.read_text())
    k1 = np.asarray(cameras["1"]["cam_K"], dtype=np.float64).reshape(3, 3)
    k1[0, 2] += 96.0  # image 1: principal point 96 px to the right, 20 % longer focal length in y
    k1[1, 1] *= 1.2
    cameras["1"]["cam_K"] = k1.ravel().tolist()
    cameras_file.write_text(json.dumps(cameras))
    k0 = np.asarray(cameras["0"]["cam_K"], dtype=np.float64).reshape(3, 3)
    config = write(tmp_path, "bop.yaml", BOP_REPLICATION_V3)
    out = tmp_path / "out"
    loaded = load_config(config, [str(tmp_path / "bop"), "lm", str(tmp_path / "toolkit"), str(out)])
    context = execute(loaded, build_modules(loaded))
    scene = context.scene
    assert [i.K.tolist() for i in scene.camera.intrinsics_per_keypoint] == [k0.tolist(), k1.tolist()]
    # the BOP writer records the K each image was rendered with: the renderer's 80 x 60 of 640 x 480
    scale = np.diag([80 / 640, 60 / 480, 1.0])
    written = json.loads((out / "bop_data" / "lm" / "train_pbr" / "000000" / "scene_camera.json").read_text())
    for image, k in (("0", k0), ("1", k1)):
        expected = scale @ k
        expected[:2, 2] = (k[:2, 2] + 0.5) * [80 / 640, 60 / 480] - 0.5  # pixel centres, as Intrinsics.resized
        np.testing.assert_allclose(np.asarray(written[image]["cam_K"]).reshape(3, 3), expected, atol=1e-9)
    # image 1's labels are those of a camera with K_1 alone (an independent single-K render)
    depth_maps = []
    for image, k in ((0, k0), (1, k1)):
        single = hg.Scene(objects=scene.objects, lights=scene.lights, world=scene.world)
        single.camera.intrinsics = hg.Intrinsics(k, 640, 480).resized(80, 60)
        single.camera.add_keypoint(scene.camera.keypoints[image])
        sink = hg.MemorySink()
        hg.render_labels(single, [sink], hg.LabelRequest(map_by=["instance"], normals=False))
        depth_maps.append(sink.stacked("depth")[0])
    assert not np.allclose(depth_maps[0], depth_maps[1], equal_nan=True)
    scene.camera.intrinsics = scene.camera.intrinsics_per_keypoint[0]
    sink = hg.MemorySink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"], normals=False))
    # the replicated scene was rendered at the BOP camera's 640 x 480 here (no renderer resolution)
    for image, k in ((0, k0), (1, k1)):
        single = hg.Scene(objects=scene.objects, lights=scene.lights, world=scene.world)
        single.camera.intrinsics = hg.Intrinsics(k, 640, 480)
        single.camera.add_keypoint(scene.camera.keypoints[image])
        alone = hg.MemorySink()
        hg.render_labels(single, [alone], hg.LabelRequest(map_by=["instance"], normals=False))
        np.testing.assert_array_equal(sink.stacked("instance_segmaps")[image], alone.stacked("instance_segmaps")[0])
        np.testing.assert_array_equal(sink.stacked("depth")[image], alone.stacked("depth")[0])
