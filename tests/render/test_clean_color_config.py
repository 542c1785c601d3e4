"""renderer.RgbRenderer's color defaults through a whole run: adaptive, clamped, denoised unless told
otherwise; ``samples: N, denoise: false`` is a plain N-spp estimate."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

import hybridgen as hg

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {global: {horizon_color: [0.3, 0.3, 0.3]}}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: ball, category_id: 2, location: [0, 0, 0.5]}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24}
      cam_poses:
        - {location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0.3]}}
  - name: renderer.RgbRenderer
    config: %s
  - name: writer.Hdf5Writer
"""


def _run(tmp_path: Path, name: str, renderer_config: str) -> h5py.File:
    out = tmp_path / name
    config = tmp_path / f"{name}.yaml"
    config.write_text(CONFIG % renderer_config)
    hg.run_config(config, [str(out)])
    return h5py.File(out / "data.hdf5")


def test_defaults_are_adaptive_clamped_and_denoised(tmp_path, gl_context):
    pytest.importorskip("pyoidn")
    with _run(tmp_path, "default", "{min_samples: 8, output_sample_counts: true, output_raw: true}") as f:
        attrs = dict(f.attrs)
        assert attrs["adaptive_sampling"] and attrs["denoised"]
        assert attrs["noise_threshold"] == 0.005 and attrs["samples"] == 768 and attrs["min_samples"] == 8
        assert attrs["max_bounces"] == 3
        counts = f["sample_counts"][0]
        assert set(np.unique(counts)) <= {8 * 2 ** k for k in range(7)} | {768}  # doubling rounds, then the rest
        assert counts.max() > counts.min() == 8  # the flat sky stops at min_samples
        assert f["colors_raw"].shape == f["colors"].shape and (f["colors_raw"][0] != f["colors"][0]).any()


def test_explicit_samples_without_denoising_are_a_plain_estimate(tmp_path, gl_context):
    config = "{samples: 4, denoise: false, output_sample_counts: true, output_hdr: true}"
    with _run(tmp_path, "a", config) as a, _run(tmp_path, "b", config) as b:
        assert not a.attrs["adaptive_sampling"] and not a.attrs["denoised"] and a.attrs["samples"] == 4
        assert (a["sample_counts"][0] == 4).all()
        assert "colors_raw" not in a
        np.testing.assert_array_equal(a["colors"][0], b["colors"][0])  # same config + seed = same bytes
