"""A BlenderProc 1.x RgbRenderer with ``render_diffuse_color`` stores Blender's Diffuse Color pass (hybridgen's
``diffuse_color``) under ``diffuse_color_output_key``: the floor (an MTL material without ``illum``: Blender's OBJ
importer gives it Specular IOR Level 0) shows its base color exactly, the ``illum 2`` boxes (Specular IOR Level
0.5, roughness 0) what their specular layer leaves of theirs - the view cosine varies, so less than the base."""
from __future__ import annotations

import numpy as np

from hybridgen.run.pipeline import run_config
from tests.blenderproc_files import read_numbered
from tests.config.test_blenderproc_configs import write, write_scene

CONFIG = """\
    {
      "version": 3,
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:2>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:1>"}},
        {"module": "camera.CameraLoader", "config": {"path": "<args:0>", "file_format": "location rotation/value",
                                                     "intrinsics": {"fov": 1, "resolution_x": 48,
                                                                    "resolution_y": 36}}},
        {"module": "renderer.RgbRenderer", "config": {"samples": 1, "render_diffuse_color": True,
                                                      "diffuse_color_output_key": "diffuse"}},
        {"module": "writer.Hdf5Writer", "config": {}}
      ]
    }
"""


def test_v1_diffuse_color_is_blenders_pass(tmp_path) -> None:
    obj = write_scene(tmp_path)
    mtl = obj.with_suffix(".mtl")
    mtl.write_text(mtl.read_text().replace("Kd 0.8 0.1 0.1\n", "Kd 0.8 0.1 0.1\nillum 2\n"))
    cams = write(tmp_path, "cams", "0 -6 6 0.785398 0 0\n")
    out = tmp_path / "out"
    run_config(write(tmp_path, "config.yaml", CONFIG), [str(cams), str(obj), str(out)])
    stored = read_numbered(out)
    assert "diffuse" in stored and "albedo" not in stored
    diffuse = np.asarray(stored["diffuse"][0])
    assert diffuse.shape == (36, 48, 3)
    pixels = diffuse.reshape(-1, 3)
    floor = np.all(np.isclose(pixels, 128 / 255, atol=1e-6), axis=1)  # Kd 0.5 as the loader keeps it (8 bits)
    red = (pixels[:, 0] > 0.5) & (pixels[:, 1] < 0.2)
    assert floor.sum() > 300 and red.sum() > 15
    # the boxes' red: 0.8 less the specular layer's share, which grows towards grazing view (Fresnel)
    assert np.all(pixels[red, 0] < 0.8 * 0.97) and np.all(pixels[red, 0] > 0.8 * 0.5)
    assert np.ptp(pixels[red, 0]) > 0.01
