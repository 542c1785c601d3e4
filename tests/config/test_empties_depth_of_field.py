"""constructor.BasicEmptyInitializer (empties: named poses, never drawn) and intrinsics.depth_of_field with a
focal object, in BlenderProc's v1.12 config form (the camera_depth_of_field example's keys)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import ConfigError
from hybridgen.modules.hdf5_writer import scene_records
from hybridgen.scene.frames import euler_xyz_to_matrix
from tests.config.test_blenderproc_modules import run_config_text


def _config(tmp_path, empties: list, dof: dict) -> str:
    return json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
            {"type": "cube", "name": "Cube", "add_properties": {"cp_category_id": 1}}]}},
        {"module": "constructor.BasicEmptyInitializer", "config": {"empties_to_add": empties}},
        {"module": "camera.CameraLoader", "config": {
            "intrinsics": {"fov": 1, "resolution_x": 64, "resolution_y": 48, "depth_of_field": dof},
            "cam_poses": [{"location": [0, -6, 2], "rotation": {"format": "look_at", "value": [0, 0, 0]}},
                          {"location": [6, 0, 2], "rotation": {"format": "look_at", "value": [0, 0, 0]}}]}}]})


FOCUS = {"fstop": 0.25, "focal_object": {"provider": "getter.Entity", "conditions": {"name": "Camera Focus Point"}}}


def test_empties_are_named_poses_the_camera_focuses_on(tmp_path):
    empties = [{"type": "plain_axes", "name": "Camera Focus Point", "location": [0.5, -1.5, 3]},
               {"type": "arrows", "name": "Camera Focus Point", "location": [1, 2, 3], "rotation": [0.1, 0.2, 0.3],
                "scale": [2, 2, 2]}]
    scene = run_config_text(tmp_path, _config(tmp_path, empties, FOCUS)).scene
    first, second = scene.empties
    assert (first.name, first.display_type) == ("Camera Focus Point", "plain_axes")
    assert (second.name, second.display_type) == ("Camera Focus Point.001", "arrows")  # Blender's next name
    np.testing.assert_allclose(first.local2world, np.array([[1, 0, 0, 0.5], [0, 1, 0, -1.5], [0, 0, 1, 3],
                                                             [0, 0, 0, 1.0]]))
    np.testing.assert_allclose(second.local2world[:3, :3], euler_xyz_to_matrix([0.1, 0.2, 0.3]) * 2)
    # the exact name selects one empty: its origin is the focus point
    dof = scene.camera.depth_of_field
    assert dof.fstop == 0.25 and dof.focus_point == (0.5, -1.5, 3.0)
    lens = 18.0 / math.tan(0.5) / 1000  # Blender: fov 1 rad on the 36 mm sensor
    assert dof.aperture_radius(scene.camera.intrinsics) == pytest.approx(lens / 0.5)
    # focus distance along each keypoint's view axis: (0, -6, 2) looking at the origin
    pose = scene.camera.keypoints[0]
    axis = -np.array([0, -6, 2.0]) / np.linalg.norm([0, -6, 2.0])
    assert dof.distance_at(pose) == pytest.approx(abs(axis @ (np.array([0.5, -1.5, 3]) - [0, -6, 2])))
    # empties are never drawn and are not objects: labels show the cube alone, object_states lists it alone
    assert [o.name for o in scene.objects] == ["Cube"]
    sink = hg.MemorySink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"]))
    assert set(np.unique(sink.stacked("instance_segmaps")).tolist()) == {0, 1}
    assert [record["name"] for record in scene_records(scene)["object_states"]] == ["Cube"]


def test_focus_distance_instead_of_an_object(tmp_path):
    scene = run_config_text(tmp_path, _config(tmp_path, [{"name": "unused"}],
                                              {"fstop": 2.8, "depth_of_field_dist": 4.5})).scene
    dof = scene.camera.depth_of_field
    assert dof.focus_point is None and dof.distance_at(scene.camera.keypoints[1]) == 4.5


@pytest.mark.parametrize("empties, dof, key, words", [
    ([{"name": "A"}, {"name": "A"}], {"focal_object": {"conditions": {"name": "A.*"}}},
     "intrinsics.depth_of_field.focal_object", "exactly one focal object, 2 match"),
    ([{"name": "A"}], {"focal_object": {"conditions": {"name": "A"}}, "depth_of_field_dist": 2},
     "intrinsics.depth_of_field", "exactly one of focal_object and depth_of_field_dist"),
    ([{"name": "A"}], {"fstop": 0, "depth_of_field_dist": 2}, "intrinsics.depth_of_field.fstop", "positive"),
    ([{"name": "A"}], {"focus": 2}, "intrinsics.depth_of_field.focus", "unknown key"),
    ([{"type": "plain_axes"}], {"depth_of_field_dist": 2}, "empties_to_add[0].name", "needs a name"),
    ([{"name": "A", "type": "torus"}], {"depth_of_field_dist": 2}, "empties_to_add[0].type", "not one of"),
    ([{"name": "A", "location": [1, 2]}], {"depth_of_field_dist": 2}, "empties_to_add[0].location", "three numbers"),
])
def test_errors_name_the_key(tmp_path, empties, dof, key, words):
    with pytest.raises(ConfigError) as info:
        run_config_text(tmp_path, _config(tmp_path, empties, dof))
    assert info.value.key == key and words in str(info.value) and "\n" not in str(info.value)
