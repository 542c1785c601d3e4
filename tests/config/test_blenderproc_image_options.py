"""BlenderProc renderer options with their meaning: image_type JPEG makes the BOP and COCO writers after the
renderer write JPEG files (as BlenderProc copies the renderer's files); use_alpha cuts texture alpha out."""
from __future__ import annotations

import io
import json

import numpy as np
from PIL import Image

from tests.config.test_blenderproc_configs import notices  # noqa: F401  (fixture)
from tests.config.test_blenderproc_modules import HEADER, run_config_text

CONFIG = HEADER + """\
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "plane", "name": "floor", "scale": [3, 3, 1], "add_properties": {"cp_category_id": 2}},
    {"type": "cube", "name": "box", "scale": [0.5, 0.5, 0.5], "location": [0, 0, 0.5],
     "add_properties": {"cp_category_id": 5}}]}},
  {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [2, -2, 5],
                                                            "energy": 800}]}},
  {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": 0.8, "resolution_x": 32, "resolution_y": 24},
     "cam_poses": [{"location": [0, -4, 4], "rotation": {"format": "look_at", "value": [0, 0, 0]}}]}},
  {"module": "renderer.RgbRenderer", "config": {"samples": 2, "image_type": "JPEG", "use_alpha": USE_ALPHA}},
  {"module": "writer.CocoAnnotationsWriter", "config": {}},
  {"module": "writer.BopWriter", "config": {"dataset": "", "append_to_existing_output": false}},
  {"module": "writer.Hdf5Writer", "config": {}}
]}
"""


def test_jpeg_image_type_gives_jpeg_files_next_to_exact_hdf5_colors(tmp_path, notices):
    import h5py

    context = run_config_text(tmp_path, CONFIG.replace("USE_ALPHA", "false") % tmp_path)
    rgb = tmp_path / "bop_data" / "train_pbr" / "000000" / "rgb" / "000000.jpg"
    coco = json.loads((tmp_path / "coco_data" / "coco_annotations.json").read_text())
    assert rgb.is_file() and [i["file_name"] for i in coco["images"]] == ["coco_data/rgb_0000.jpg"]
    jpeg = Image.open(io.BytesIO(rgb.read_bytes()))
    assert jpeg.format == "JPEG"
    with h5py.File(tmp_path / "0.hdf5") as f:  # BlenderProc's per-keypoint file
        exact = np.asarray(f["colors"][()])
    decoded = np.asarray(jpeg.convert("RGB"), dtype=np.int16)
    assert decoded.shape == exact.shape and np.abs(decoded - exact).mean() < 6  # quality 95: close, lossy
    assert any("image_type" in line and "JPEG" in line for line in notices)
    assert all(o.material.alpha_mode == "BLEND" for o in context.scene.objects)  # use_alpha false: default


def test_use_alpha_clips_texture_alpha(tmp_path, notices):
    context = run_config_text(tmp_path, CONFIG.replace("USE_ALPHA", "true") % tmp_path)
    assert all(o.material.alpha_mode == "CLIP" for o in context.scene.objects)
    assert any("use_alpha" in line for line in notices)
