"""composite.CameraObjectSampler: object poses change every few cameras, and every keypoint's labels, color
and BOP annotations show the objects where they stood when its camera was sampled."""
from __future__ import annotations

import json

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import ConfigError
from hybridgen.scene.object_keyframes import ObjectKeyframes
from tests.config.test_blenderproc_modules import HEADER, run_config_text
from tests.conftest import silhouette

# A 0.2 m cube re-placed every 2 of 4 cameras; all cameras 4 m above the origin looking at the cube
# (getter.POI with an empty parameters mapping); the BOP writer annotates every image.
CONFIG = HEADER + """\
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "cube", "name": "Cube", "scale": [0.1, 0.1, 0.1], "add_properties": {"cp_category_id": 1,
                                                                 "cp_bop_dataset_name": "stand"}}]}},
  {"module": "composite.CameraObjectSampler", "config": {
    "total_noof_cams": 4, "noof_cams_per_scene": 2,
    "object_pose_sampler": {"module": "object.ObjectPoseSampler", "config": {
      "pos_sampler": {"provider": "sampler.Uniform3d", "max": [0.8, 0.6, 0], "min": [-0.8, -0.6, 0]},
      "rot_sampler": {"provider": "sampler.Uniform3d", "max": [0, 0, 6.28], "min": [0, 0, 0]}}},
    "camera_pose_sampler": {"module": "camera.CameraSampler", "config": {
      "intrinsics": {"resolution_x": 64, "resolution_y": 48, "fov": 0.9},
      "cam_poses": [{"location": [0, 0, 4], "rotation": {"format": "look_at", "value": {"provider": "getter.POI",
                                                                    "parameters": {}}}}]}}}},
  {"module": "renderer.RgbRenderer", "config": {"samples": 4}},
  {"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance", "class"]}},
  {"module": "writer.BopWriter", "config": {"dataset": "stand", "append_to_existing_output": false}}
]}
"""


def test_objects_are_resampled_every_few_cameras_and_annotated_where_they_stood(tmp_path):
    context = run_config_text(tmp_path, CONFIG % tmp_path)
    scene = context.scene
    keyframes = scene.object_keyframes
    assert len(scene.camera) == 4 and keyframes.starts == [0, 2]
    cube = scene.by_name("Cube")
    first, second = (keyframes.poses[g][cube.instance_id] for g in (0, 1))
    for pose in (first, second):  # drawn inside the sampling box, upright, at z = 0, scale kept
        assert abs(pose[0, 3]) <= 0.8 and abs(pose[1, 3]) <= 0.6 and pose[2, 3] == 0
        np.testing.assert_allclose(np.linalg.norm(pose[:3, :3], axis=0), [0.1] * 3, atol=1e-12)
        np.testing.assert_allclose(pose[:3, 2], [0, 0, 0.1], atol=1e-12)
    assert np.linalg.norm(first[:3, 3] - second[:3, 3]) > 1e-3
    np.testing.assert_allclose(cube.local2world, second)  # the scene is left as the last keypoint shows it
    # POI of the (only) object: every camera looks from straight above it ... BlenderProc's POI is the mean
    # of the objects' bounding-box centres at the time the camera is sampled
    for index, pose in enumerate(scene.camera.keypoints):
        expected = (first if index < 2 else second)[:3, 3]
        forward = pose[:3, 2]  # OpenCV camera +z
        np.testing.assert_allclose(forward, (expected - [0, 0, 4]) / np.linalg.norm(expected - [0, 0, 4]),
                                   atol=1e-9)
    # BOP scene_gt: the model-to-camera translation of each image is the cube of its group (mm)
    chunk = tmp_path / "bop_data" / "stand" / "train_pbr" / "000000"
    gt = json.loads((chunk / "scene_gt.json").read_text())
    for index, pose in enumerate(scene.camera.keypoints):
        expected = np.linalg.inv(pose) @ (first if index < 2 else second)
        np.testing.assert_allclose(gt[str(index)][0]["cam_t_m2c"], expected[:3, 3] * 1000, atol=1e-3)
    # the visible pixels BOP counts are the cube's top face: 0.2 m square seen from 3.9 m
    info = json.loads((chunk / "scene_gt_info.json").read_text())
    focal = 32 / np.tan(0.45)
    for index in range(4):
        assert info[str(index)][0]["px_count_visib"] == pytest.approx((0.2 * focal / 3.9) ** 2, rel=0.35)


def _plane(name: str, emission: float) -> hg.MeshObject:
    plane = hg.make_primitive("plane", 0.4, name=name, category_id=1)
    plane.material.emission, plane.material.emission_strength = (1.0, 1.0, 1.0), emission
    plane.material.base_color = (0.0, 0.0, 0.0, 1.0)
    return plane


def test_labels_and_color_follow_the_keyframed_poses():
    """Two keypoints of one camera pose; an emissive square moves between them. The raster's instance map and
    Mitsuba's color both show it where the keyframe puts it (the square's projection is known exactly)."""
    scene = hg.Scene()
    scene.world = hg.World(color=(0.0, 0.0, 0.0), strength=0.0)
    square = scene.add(_plane("square", 5.0))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 64, 48)
    camera = np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV axes looking down -Z from 3 m
    camera[:3, 3] = [0, 0, 3]
    keyframes = ObjectKeyframes()
    places = ([-0.6, 0.3, 0.0], [0.5, -0.4, 0.0])
    for place in places:
        square.local2world = np.eye(4)
        square.local2world[:3, 3] = place
        keyframes.record(scene)
        scene.camera.add_keypoint(camera)
    scene.object_keyframes = keyframes
    sink = hg.MemorySink()
    settings = hg.PathTraceSettings(samples=4)
    hg.render_color(scene, [sink], settings, labels=hg.LabelRequest(map_by=["instance"]), seed=1, hdr=True)
    instance, radiance = sink.stacked("instance_segmaps"), sink.stacked("colors_hdr").astype(np.float64)
    intr = scene.camera.intrinsics
    rows, cols = np.mgrid[0:intr.height, 0:intr.width]
    for index, place in enumerate(places):
        # the centre of the square projects to (cx + f x / 3, cy + f (-y) / 3); pixel centres are integers
        expected = (intr.K[0, 2] + intr.K[0, 0] * place[0] / 3.0, intr.K[1, 2] + intr.K[1, 1] * -place[1] / 3.0)
        mask = instance[index] == square.instance_id
        assert (cols[mask].mean(), rows[mask].mean()) == pytest.approx(expected, abs=0.5)  # whole pixels
        # Mitsuba: the emitted light is centred there too (a symmetric pixel filter keeps the centroid) ...
        weight = radiance[index].sum(axis=-1)
        centroid = ((weight * cols).sum() / weight.sum(), (weight * rows).sum() / weight.sum())
        assert centroid == pytest.approx(expected, abs=0.3)
        # ... and nothing shines where the square stands at the other keypoint
        other = instance[1 - index] == square.instance_id
        assert weight[other & ~mask & ~silhouette(instance[1 - index])].max(initial=0.0) == 0.0
    assert not np.array_equal(instance[0], instance[1])


def test_a_nested_entry_with_a_bad_key_names_it(tmp_path):
    text = (CONFIG % tmp_path).replace('"max_iterations"', '"max_iterations"').replace(
        '"pos_sampler"', '"pos_sampl"')
    with pytest.raises(ConfigError) as info:
        run_config_text(tmp_path, text)
    message = str(info.value)
    assert "composite.CameraObjectSampler" in message and "object_pose_sampler" in message
    assert "pos_sampl" in message
