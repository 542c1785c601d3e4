"""Keys BlenderProc itself does not read are dropped with one notice each, as BlenderProc skips them: a module key
put inside a getter.Entity selector, a CameraLoader pose's rotation_euler."""
from __future__ import annotations

import json

import numpy as np

from hybridgen.config.notices import set_sink
from tests.config.test_blenderproc_modules import run_config_text


def test_keys_blenderproc_skips_are_notices(tmp_path):
    text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [{"type": "plane",
                                                                                     "name": "Ceiling"}]}},
        {"module": "lighting.SurfaceLighting", "config": {"selector": {
            "provider": "getter.Entity", "conditions": {"name": "Ceiling"}, "emission_strength": 4.0}}},
        {"module": "camera.CameraLoader", "config": {"cam_poses": [
            {"location": [0, 0, 5], "rotation_euler": [1.0, 0, 0]}]}}]})
    lines: list[str] = []
    set_sink(lines.append)
    try:
        context = run_config_text(tmp_path, text)
    finally:
        set_sink(None)
    assert any("selector.emission_strength" in line and "ignored" in line for line in lines)
    assert any("cam_poses[0].rotation_euler" in line and "ignored" in line for line in lines)
    ceiling = context.scene.by_name("Ceiling")
    assert ceiling.material.emission_strength == 10.0  # SurfaceLighting's default, as BlenderProc uses it
    # rotation_euler is not read: the camera keeps rotation 0 (looking straight down from 5 m)
    np.testing.assert_allclose(context.scene.camera.keypoints[0][:3, 2], [0, 0, -1], atol=1e-12)
