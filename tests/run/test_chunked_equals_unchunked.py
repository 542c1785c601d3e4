"""A chunked run is the same scene as the unchunked run of the same config, keypoint for keypoint.

`keypoints_per_chunk` only decides how the work is cut; it must not change what is rendered. The unchunked
run (one unit per scene, in this process) is the reference; the chunked run goes through the process pool
and through a real local Ray cluster. Every dataset of the index - object_states, cam2world, labels and the
path-traced color - must be equal array for array (the files' bytes differ: they record their output folder).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from tests.conftest import REPO

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 11, number_of_scenes: 2, keypoints_per_chunk: %d}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.6, name: ball, category_id: 2,
             location: {provider: sampler.Uniform3d, min: [-1, -1, 0.3], max: [1, 1, 0.3]},
             color: {provider: sampler.Color, min: [0.1, 0.1, 0.1, 1], max: [0.9, 0.9, 0.9, 1]}}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.4, name: box, category_id: 3,
             location: {provider: sampler.Uniform3d, min: [-1.5, -1.5, 0.2], max: [1.5, 1.5, 0.2]},
             rotation: {provider: sampler.Uniform3d, min: [0, 0, 0], max: [0, 0, 6.28]}}
  - name: lighting.LightLoader
    config: {lights: [{type: POINT, name: bulb, energy: {provider: sampler.Value, type: float, min: 50, max: 300},
                       location: [1, -1, 3]}]}
  - name: camera.CameraSampler
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24}
      cam_poses:
        - number_of_samples: 5
          location: {provider: sampler.Shell, center: [0, 0, 0], radius_min: 2, radius_max: 4,
                     elevation_min: 20, elevation_max: 60}
          rotation: {format: look_at, value: {provider: getter.POI, selector: {name: ball}}}
  - name: renderer.RgbRenderer
    config: {samples: 2, max_bounces: 1, denoise: false, render_depth: true, render_normals: true,
             map_by: [class, instance]}
  - name: writer.Hdf5Writer
"""


def _run(config: Path, out: Path, *extra: str) -> None:
    done = subprocess.run([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(out), *extra],
                          cwd=REPO, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]


def _datasets(path: Path) -> dict[str, np.ndarray]:
    with h5py.File(path) as f:
        return {key: f[key][()] for key in f if isinstance(f[key], h5py.Dataset)}


@pytest.fixture(scope="module")
def unchunked(tmp_path_factory: pytest.TempPathFactory, gl_context) -> dict[str, np.ndarray]:
    folder = tmp_path_factory.mktemp("unchunked")
    config = folder / "config.yaml"
    config.write_text(CONFIG % 0)
    from hybridgen.cli import main

    assert main(["run", "-q", str(config), str(folder / "out")]) == 0
    assert len(list((folder / "out/shards").glob("scene_*.hdf5"))) == 2  # one unit per scene
    return _datasets(folder / "out/data.hdf5")


def _assert_same_scenes(chunked: dict[str, np.ndarray], reference: dict[str, np.ndarray]) -> None:
    assert sorted(chunked) == sorted(reference)
    for key in ("colors", "depth", "normals", "instance_segmaps", "category_id_segmaps", "cam2world", "cam_K"):
        assert key in reference
    assert reference["colors"].shape == (10, 24, 32, 3)
    for key, value in reference.items():
        if value.dtype.kind in "OS":  # JSON text: compare the parsed values
            parsed = lambda v: [json.loads(x) for x in np.atleast_1d(v)]  # noqa: E731
            assert parsed(chunked[key]) == parsed(value), key
        else:
            np.testing.assert_array_equal(chunked[key], value, err_msg=key)
    # the scenes themselves differ from each other (their own seeds), and the ball moved between them
    states = [json.loads(s) for s in reference["object_states"]]
    balls = [np.array(next(o for o in scene if o["name"] == "ball")["local2world"]) for scene in states]
    assert not np.allclose(balls[0], balls[1])


def test_chunked_pool_run_equals_the_unchunked_run(unchunked, tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text(CONFIG % 2)
    _run(config, tmp_path / "out", "--workers", "2")
    assert len(list((tmp_path / "out/shards").glob("scene_*.hdf5"))) == 6  # 2 scenes x 3 chunks
    _assert_same_scenes(_datasets(tmp_path / "out/data.hdf5"), unchunked)


def test_chunked_ray_run_equals_the_unchunked_run(unchunked, tmp_path):
    """The run starts its own local Ray cluster (bound to 127.0.0.1, no dashboard; see docs)."""
    pytest.importorskip("ray")
    config = tmp_path / "config.yaml"
    config.write_text(CONFIG % 3)
    _run(config, tmp_path / "out", "--executor", "ray", "--workers", "2")
    assert len(list((tmp_path / "out/shards").glob("scene_*.hdf5"))) == 4  # 2 scenes x 2 chunks
    _assert_same_scenes(_datasets(tmp_path / "out/data.hdf5"), unchunked)
