"""BlenderProc layout: one <i>.hdf5 per keypoint with BlenderProc's keys and encodings; its viewer opens them."""
from __future__ import annotations

import json
import shutil
import subprocess

import h5py
import numpy as np
import pytest

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: ball, category_id: 2, location: [0, 0, 0.5]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 48, resolution_y: 32}
      cam_poses:
        - {location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
        - {location: [-3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - name: renderer.RgbRenderer
    config: {samples: 1, render_depth: true, render_normals: true, normals_space: %s, map_by: [class, instance]}
  - name: writer.Hdf5Writer
    config: {layout: %s, append_to_existing_output: true%s}
"""


def _run(run_cli, write_config, out, layout, space="camera"):
    # the single file stores the documented dtypes as they are, so normals compare to 1e-6
    extra = ", encoding: plain" if layout == "single" else ""
    code, _, err = run_cli("run", "-q", str(write_config(CONFIG % (space, layout, extra), f"{layout}{space}.yaml")),
                           str(out))
    assert code == 0, err


def test_per_keypoint_files_match_the_single_file(gl_context, tmp_path, run_cli, write_config):
    _run(run_cli, write_config, tmp_path / "single", "single")
    _run(run_cli, write_config, tmp_path / "bp", "blenderproc", space="world")
    assert sorted(p.name for p in (tmp_path / "bp").iterdir()) == ["0.hdf5", "1.hdf5"]
    with h5py.File(tmp_path / "single/data.hdf5") as single:
        for index in range(2):
            with h5py.File(tmp_path / f"bp/{index}.hdf5") as bp:
                for key in ("colors", "depth", "instance_segmaps", "category_id_segmaps"):
                    np.testing.assert_array_equal(bp[key][()], single[key][index])
                    assert single[key].dtype == bp[key].dtype, key
                # normals: camera frame, Blender axes (y, z negated), 0.5 n + 0.5 (written from world normals here)
                expected = 0.5 * single["normals"][index] * np.array([1, -1, -1]) + 0.5
                np.testing.assert_allclose(bp["normals"][()], expected, atol=1e-6)
                visible = json.loads(bp["instance_attribute_maps"][()])
                assert visible == json.loads(single["instance_attribute_maps"][index])
                state = json.loads(bp["cam_states"][()])
                blender = np.array(state["cam2world_matrix"])
                np.testing.assert_allclose(blender @ np.diag([1, -1, -1, 1]), single["cam2world"][index], atol=1e-12)
                np.testing.assert_allclose(state["cam_K"], single["cam_K"][index])
                assert [o["name"] for o in json.loads(bp["object_states"][()])] == ["floor", "ball"]
    # append continues the numbering
    _run(run_cli, write_config, tmp_path / "bp", "blenderproc")
    assert sorted(p.name for p in (tmp_path / "bp").iterdir()) == ["0.hdf5", "1.hdf5", "2.hdf5", "3.hdf5"]


@pytest.mark.skipif(shutil.which("blenderproc") is None and not __import__("importlib").util.find_spec("blenderproc"),
                    reason="blenderproc (the viewer) is not installed")
def test_blenderprocs_own_viewer_opens_them(gl_context, tmp_path, run_cli, write_config):
    import sys
    from pathlib import Path

    _run(run_cli, write_config, tmp_path / "bp", "blenderproc")
    viewer = Path(sys.executable).with_name("blenderproc")
    done = subprocess.run([str(viewer), "vis", "hdf5", str(tmp_path / "bp/0.hdf5"), "--save", str(tmp_path / "vis")],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    written = sorted(p.name for p in (tmp_path / "vis").iterdir())
    assert {"0_colors.png", "0_depth.png", "0_normals.png", "0_instance_segmaps.png"} <= set(written)
