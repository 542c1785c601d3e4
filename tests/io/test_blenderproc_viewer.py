"""BlenderProc's own viewer (`blenderproc vis hdf5 --save`) on our BlenderProc-layout files: its PNGs, decoded
here, show our arrays - colors byte for byte, normals as 0.5 n + 0.5, depth through its 'summer' colormap
(red = (d - min) / (20 m - min)), segmentation as the same partition of the image."""
from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from tests.io.test_extract import decode_png

pytestmark = pytest.mark.skipif(importlib.util.find_spec("blenderproc") is None,
                                reason="blenderproc (the viewer) is not installed")

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {horizon_color: [0.2, 0.3, 0.5]}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1, color: [0.8, 0.5, 0.2]}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: ball, category_id: 2, location: [0, 0, 0.5], color: [0.1, 0.7, 0.3]}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.6, name: box, category_id: 3, location: [0.9, -0.9, 0.3]}
  - name: lighting.LightLoader
    config: {lights: [{type: SUN, name: sun, energy: 2.0, rotation: [0.5, 0.2, 0.3]}]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 48, resolution_y: 32}
      cam_poses:
        - {location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - name: renderer.RgbRenderer
    config: {samples: 2, max_bounces: 1, denoise: false, render_depth: true, render_normals: true,
             map_by: [class, instance]}
  - name: writer.Hdf5Writer
    config: {layout: blenderproc}
"""


def test_blenderprocs_viewer_pngs_show_our_arrays(gl_context, tmp_path, run_cli, write_config):
    code, _, err = run_cli("run", "-q", str(write_config(CONFIG, "bp.yaml")), str(tmp_path / "bp"))
    assert code == 0, err
    viewer = Path(sys.executable).with_name("blenderproc")
    done = subprocess.run([str(viewer), "vis", "hdf5", str(tmp_path / "bp/0.hdf5"), "--save", str(tmp_path / "vis")],
                          capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    png = lambda key: decode_png(tmp_path / f"vis/0_{key}.png").astype(np.int64)  # noqa: E731 (RGBA)
    with h5py.File(tmp_path / "bp/0.hdf5") as f:
        colors, normals, depth = f["colors"][()], f["normals"][()], f["depth"][()]
        instance, category = f["instance_segmaps"][()], f["category_id_segmaps"][()]
    assert len(np.unique(colors.reshape(-1, 3), axis=0)) > 20 and len(np.unique(instance)) == 4

    shown = png("colors")
    np.testing.assert_array_equal(shown[..., :3], colors)
    assert (shown[..., 3] == 255).all()

    # matplotlib stores float RGB in [0, 1] as uint8(x * 255)
    np.testing.assert_allclose(png("normals")[..., :3], normals.astype(np.float64) * 255, atol=1.0)

    # depth: colormap 'summer' (r, g, b) = (x, 0.5 + x / 2, 0.4) of x = (d - d.min()) / (20 - d.min()), clipped
    finite = np.isfinite(depth)
    low = depth[finite].min()
    x = np.clip((np.where(finite, depth, 20.0) - low) / (20.0 - low), 0, 1)
    red = png("depth")[..., 0]
    lut_index = np.minimum(np.floor(x * 256), 255)  # a 256-entry colormap, entry i has red i / 255
    assert np.abs(red - lut_index).max() <= 1
    assert (red[~finite] == 255).all() and finite.sum() > 100

    for key, ids in (("instance_segmaps", instance), ("category_id_segmaps", category)):
        image = png(key)[..., :3]
        colors_of = {int(i): {tuple(c) for c in image[ids == i]} for i in np.unique(ids)}
        assert all(len(c) == 1 for c in colors_of.values()), key          # one color per id ...
        assert len({next(iter(c)) for c in colors_of.values()}) == len(colors_of), key  # ... a different one each
