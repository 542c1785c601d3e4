"""A BlenderProc 1.x config's writer.Hdf5Writer writes BlenderProc's files: ``<output_dir>/<i>.hdf5`` with its
keys, dtypes and encodings (colors uint8, depth/distance float32 - three equal channels where no
TrimRedundantChannels trimmed them -, normals float32 in Blender camera axes as 0.5 n + 0.5, segmap float64,
``<key>_version`` beside each), checked against the analytic scene and against hybridgen's own data.hdf5 of
the same config; BlenderProc's own viewer opens them."""
from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.run.pipeline import run_config
from tests.blenderproc_files import numbered_files

FOV, W, H = 0.8, 32, 24
# A 6 m floor (class 2) and a 1 m cube on it (class 5); two cameras look straight down (Blender rotation 0
# looks along -Z) from 5 m and 4 m, so floor depth is 5 / 4 and the cube's top 4 / 3 (m).
CONFIG = """\
{"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
  {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:0>"}}},
  {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
    {"type": "plane", "name": "floor", "scale": [3, 3, 1], "add_properties": {"cp_category_id": 2}},
    {"type": "cube", "name": "box", "scale": [0.5, 0.5, 0.5], "location": [0, 0, 0.5],
     "add_properties": {"cp_category_id": 5}}]}},
  {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [1, -1, 4], "energy": 300}]}},
  {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": %s, "resolution_x": %d, "resolution_y": %d},
     "cam_poses": [{"location": [0, 0, 5], "rotation": {"value": [0, 0, 0]}},
                   {"location": [0, 0, 4], "rotation": {"value": [0, 0, 0]}}]}},
  {"module": "renderer.RgbRenderer", "config": {"samples": 2, "render_normals": true, "render_distance": true,
                                                "render_depth": true}},
  {"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance", "class"]}},
  {"module": "writer.Hdf5Writer", "config": {WRITER
     "postprocessing_modules": {"distance": [{"module": "postprocessing.TrimRedundantChannels"}]}}}
]}
""" % (FOV, W, H)


def _run(tmp_path: Path, name: str, writer: str = "", append: bool = False) -> Path:
    config = tmp_path / f"{name}.yaml"
    config.write_text(CONFIG.replace("WRITER", writer + (' "append_to_existing_output": true,' if append else "")))
    out = tmp_path / name
    run_config(config, [str(out)])
    return out


def _ray_lengths() -> np.ndarray:
    """Per pixel, the length of the camera ray with unit depth (OpenCV pixel centres, fx = fy from the fov)."""
    f = W / (2 * np.tan(FOV / 2))
    u, v = np.meshgrid(np.arange(W) - (W - 1) / 2, np.arange(H) - (H - 1) / 2)
    return np.sqrt(1 + (u / f) ** 2 + (v / f) ** 2)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    tmp_path = tmp_path_factory.mktemp("v1")
    # the same config, once as written (BlenderProc's files) and once asking for hybridgen's single file
    return _run(tmp_path, "bp"), _run(tmp_path, "single", '"layout": "single", "encoding": "plain",')


def test_numbered_files_with_blenderprocs_keys_and_dtypes(runs):
    bp, _ = runs
    assert [p.name for p in numbered_files(bp)] == ["0.hdf5", "1.hdf5"] and not (bp / "data.hdf5").exists()
    with h5py.File(bp / "0.hdf5") as f:
        shapes = {key: (f[key].shape, f[key].dtype) for key in ("colors", "depth", "distance", "normals", "segmap")}
        assert shapes == {"colors": ((H, W, 3), np.uint8), "depth": ((H, W, 3), np.float32),
                          "distance": ((H, W), np.float32), "normals": ((H, W, 3), np.float32),
                          "segmap": ((H, W, 2), np.float64)}
        for key in ("colors", "depth", "distance", "normals", "segmap"):
            assert f[f"{key}_version"][()].tolist() == [b"2.0.0"], key
        state = json.loads(f["cam_states"][()])  # Blender axes: rotation 0 at (0, 0, 5)
        expected = np.eye(4)
        expected[2, 3] = 5.0
        np.testing.assert_allclose(state["cam2world_matrix"], expected, atol=1e-9)


def test_values_match_the_scene_and_hybridgens_own_file(runs):
    bp, single = runs
    rays = _ray_lengths()
    with h5py.File(single / "data.hdf5") as own:
        for index, height in enumerate((5.0, 4.0)):
            with h5py.File(bp / f"{index}.hdf5") as f:
                depth, distance, normals = f["depth"][()], f["distance"][()], f["normals"][()]
                segmap = f["segmap"][()]
                # untrimmed depth: three equal channels; the floor at `height`, the cube's top 1 m nearer
                assert (depth[..., 0] == depth[..., 1]).all() and (depth[..., 0] == depth[..., 2]).all()
                floor, box = segmap[..., 1] == 2, segmap[..., 1] == 5
                assert floor.sum() > 50 and box.sum() > 20 and (floor | box).all()
                np.testing.assert_allclose(depth[..., 0][floor], height, rtol=1e-5)
                np.testing.assert_allclose(depth[..., 0][box], height - 1.0, rtol=1e-5)
                np.testing.assert_allclose(distance, depth[..., 0] * rays, rtol=1e-5)
                # every surface faces the camera (+z of Blender's camera axes): 0.5 n + 0.5 = (0.5, 0.5, 1)
                np.testing.assert_allclose(normals.reshape(-1, 3), [[0.5, 0.5, 1.0]] * (H * W), atol=1e-5)
                # the same numbers as hybridgen's own file, in BlenderProc's encodings
                np.testing.assert_array_equal(f["colors"][()], own["colors"][index])
                np.testing.assert_array_equal(depth[..., 0], own["depth"][index])
                np.testing.assert_array_equal(distance, own["distance"][index])
                expected = 0.5 * own["normals"][index] * np.array([1, -1, -1], np.float32) + 0.5
                np.testing.assert_allclose(normals, expected, atol=1e-6)
                np.testing.assert_array_equal(segmap[..., 0], own["instance_segmaps"][index])
                np.testing.assert_array_equal(segmap[..., 1], own["category_id_segmaps"][index])


def test_append_to_existing_output_continues_the_numbering(tmp_path):
    out = _run(tmp_path, "bp", append=True)
    first = (out / "1.hdf5").read_bytes()
    _run(tmp_path, "bp", append=True)
    assert [p.name for p in numbered_files(out)] == ["0.hdf5", "1.hdf5", "2.hdf5", "3.hdf5"]
    assert (out / "1.hdf5").read_bytes() == first
    with h5py.File(out / "0.hdf5") as a, h5py.File(out / "2.hdf5") as b:
        np.testing.assert_array_equal(a["depth"][()], b["depth"][()])


@pytest.mark.skipif(importlib.util.find_spec("blenderproc") is None, reason="blenderproc (the viewer) is not installed")
def test_blenderprocs_viewer_opens_them(runs, tmp_path):
    bp, _ = runs
    viewer = Path(sys.executable).with_name("blenderproc")
    done = subprocess.run([str(viewer), "vis", "hdf5", str(bp / "1.hdf5"), "--save", str(tmp_path / "vis")],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    written = {p.name for p in (tmp_path / "vis").iterdir()}
    assert {"1_colors.png", "1_depth.png", "1_distance.png", "1_normals.png"} <= written
    assert {"1_segmap_0.png", "1_segmap_1.png"} <= written or "1_segmap.png" in written
