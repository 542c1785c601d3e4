"""write_hdf5(stereo_separate_keys=True) as BlenderProc 2.8 writes it: with stereo rendering on, every key's value
of a frame is split into ``<key>_0`` (left) and ``<key>_1`` (right) - a list such as instance_attribute_maps too,
element by element; with stereo off, only arrays whose first axis has 2 entries are split."""
from __future__ import annotations

import json

import h5py
import numpy as np

from writer_session import bproc  # noqa: F401 - the fixture


def _read(path) -> dict:
    with h5py.File(path, "r") as f:
        return {key: f[key][()] for key in f.keys()}


def test_stereo_keys_are_split(bproc, tmp_path) -> None:  # noqa: F811
    bproc.camera.add_camera_pose(np.eye(4))
    bproc.renderer.toggle_stereo(True)
    colors = np.arange(2 * 4 * 5 * 3, dtype=np.uint8).reshape(2, 4, 5, 3)
    depth = np.stack([np.full((4, 5), 1.5, np.float32), np.full((4, 5), 2.5, np.float32)])
    data = {"colors": [colors], "depth": [depth], "instance_attribute_maps": [[{"idx": 0}, {"idx": 1}]]}
    bproc.writer.write_hdf5(str(tmp_path), data, stereo_separate_keys=True)
    stored = _read(tmp_path / "0.hdf5")
    assert np.array_equal(stored["colors_0"], colors[0]) and np.array_equal(stored["colors_1"], colors[1])
    assert np.all(stored["depth_0"] == 1.5) and np.all(stored["depth_1"] == 2.5)
    assert json.loads(stored["instance_attribute_maps_0"]) == {"idx": 0}
    assert json.loads(stored["instance_attribute_maps_1"]) == {"idx": 1}
    assert "colors" not in stored and "depth" not in stored


def test_mono_splits_only_pairs(bproc, tmp_path) -> None:  # noqa: F811
    bproc.camera.add_camera_pose(np.eye(4))
    colors = np.zeros((4, 5, 3), np.uint8)
    pair = np.array([[1.0, 2.0], [3.0, 4.0]])
    bproc.writer.write_hdf5(str(tmp_path), {"colors": [colors], "pair": [pair], "maps": [[{"idx": 0}]]},
                            stereo_separate_keys=True)
    stored = _read(tmp_path / "0.hdf5")
    assert stored["colors"].shape == (4, 5, 3) and json.loads(stored["maps"]) == [{"idx": 0}]
    assert np.array_equal(stored["pair_0"], [1.0, 2.0]) and np.array_equal(stored["pair_1"], [3.0, 4.0])
