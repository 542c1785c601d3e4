"""BlenderProc's SegMapRenderer: one segmap dataset (renamed by output_key) with a channel per numeric map_by
attribute in map_by order, default_values for objects lacking one, text attributes in the attribute map."""
from __future__ import annotations

import json

import numpy as np
import pytest

from hybridgen.errors import HybridgenError
from hybridgen.run.pipeline import run_config
from tests.blenderproc_files import read_numbered

# A 6 m floor (class 2, weight 7 by default, kind "floor") and a 1 m cube on it (class 5, weight 3, no kind);
# the camera looks straight down at the cube from 5 m (Blender rotation 0 looks along -Z).
CONFIG = """\
{"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
  {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:0>"}}},
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "plane", "name": "floor", "scale": [3, 3, 1],
     "add_properties": {"cp_category_id": 2, "cp_kind": "floor"}},
    {"type": "cube", "name": "box", "scale": [0.5, 0.5, 0.5], "location": [0, 0, 0.5],
     "add_properties": {"cp_category_id": 5, "cp_weight": 3}}]}},
  {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": 0.8, "resolution_x": 32, "resolution_y": 24},
     "cam_poses": [{"location": [0, 0, 5], "rotation": {"value": [0, 0, 0]}}]}},
  {"module": "renderer.SegMapRenderer", "config": {"map_by": MAP_BY, "default_values": DEFAULTS OUTPUT}},
  {"module": "writer.Hdf5Writer", "config": {}}
]}
"""


def _run(tmp_path, map_by, defaults, output=""):
    tmp_path.mkdir(exist_ok=True)
    text = CONFIG.replace("MAP_BY", json.dumps(map_by)).replace("DEFAULTS", json.dumps(defaults))
    text = text.replace(" OUTPUT", f', "output_key": "{output}"' if output else "")
    config = tmp_path / "config.yaml"
    config.write_text(text)
    out = tmp_path / "out"
    run_config(config, [str(out)])
    return read_numbered(out)  # BlenderProc's 0.hdf5: one value per key


def test_one_segmap_with_a_channel_per_numeric_attribute(tmp_path):
    data = _run(tmp_path, ["instance", "class", "name", "cp_kind", "cp_weight"],
                {"cp_weight": 7, "cp_kind": "none"}, output="my_segmap")
    assert "segmap" not in data
    segmap = np.asarray(data["my_segmap"])[0]
    assert segmap.shape == (24, 32, 3)  # instance, class, weight; name and kind are text: no channel
    assert segmap.dtype == np.float64  # as BlenderProc 1.x stores it (its channels are built in float64)
    instance = np.asarray(data["instance_segmaps"])[0]
    np.testing.assert_array_equal(segmap[..., 0], instance)
    # the cube covers the image centre, the floor the corners (geometry, not the renderer's tables)
    centre, corner = (12, 16), (0, 0)
    assert tuple(segmap[centre]) == (2, 5, 3)  # box: instance 2, class 5, weight 3
    assert tuple(segmap[corner]) == (1, 2, 7)  # floor: instance 1, class 2, weight 7 from default_values
    maps = data["instance_attribute_maps"][0]
    maps = json.loads(maps) if isinstance(maps, (bytes, str)) else maps
    by_name = {m["name"]: m for m in maps}
    assert by_name["box"]["kind"] == "none" and by_name["floor"]["kind"] == "floor"


def test_one_channel_is_an_image_and_class_is_the_default(tmp_path):
    data = _run(tmp_path, "class", {})
    segmap = np.asarray(data["segmap"])[0]
    assert segmap.shape == (24, 32)
    assert segmap[12, 16] == 5 and segmap[0, 0] == 2


def test_an_attribute_some_object_lacks_needs_a_default(tmp_path):
    with pytest.raises(HybridgenError, match="'floor' has no 'weight'.*default_values"):
        _run(tmp_path, ["instance", "cp_weight"], {})


def test_a_channel_only_default_values_fill_is_dropped(tmp_path):
    # no object has a 'score' of its own: BlenderProc keeps no channel for it; 'weight' (the box's own 3) stays
    data = _run(tmp_path, ["instance", "cp_score", "cp_weight"], {"cp_score": 4, "cp_weight": 7})
    segmap = np.asarray(data["segmap"])[0]
    assert segmap.shape == (24, 32, 2)  # instance, weight
    assert tuple(segmap[12, 16]) == (2, 3) and tuple(segmap[0, 0]) == (1, 7)
    np.testing.assert_array_equal(np.asarray(data["score_segmaps"])[0], 4)  # hybridgen's own pass stays
    with pytest.raises(HybridgenError, match="every object takes score from default_values"):
        _run(tmp_path / "single", ["cp_score"], {"cp_score": 4})
