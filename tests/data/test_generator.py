"""hybridgen.data.GeneratorDataset: the same seed gives the same samples whatever the worker count; scene s
equals scene s of `hybridgen run`; labels-only equals the color run's labels; nothing written unless asked."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.data import GeneratorDataset, KeypointDataset
from hybridgen.errors import InputError
from tests.data.scenes import config_text

LABELS = ("depth", "distance", "normals", "instance_segmaps", "category_id_segmaps", "part_segmaps", "albedo",
          "forward_flow", "backward_flow_occluded", "nocs", "cam_K", "cam2world")


def _config(tmp_path: Path, **options) -> Path:
    path = tmp_path / "generator.yaml"
    path.write_text(config_text(**options))
    return path


def _key(sample: dict) -> tuple[int, int]:
    return sample["scene_index"], sample["keypoint_index"]


def _assert_equal(a: dict, b: dict, keys) -> None:
    assert _key(a) == _key(b)
    for key in keys:
        value = a[key].numpy() if hasattr(a[key], "numpy") else a[key]  # a DataLoader gives tensors
        if isinstance(value, np.ndarray):
            assert value.dtype == b[key].dtype, key
            if key == "normals":  # a written file may hold them as octahedral codes (error < 1e-4 rad)
                np.testing.assert_allclose(value, b[key], atol=2e-4, err_msg=f"{key} of {_key(a)}")
            else:
                np.testing.assert_array_equal(value, b[key], err_msg=f"{key} of {_key(a)}")
        else:
            assert value == b[key], key


def test_in_process_order_labels_only_and_nothing_written(gl_context, tmp_path):
    out = tmp_path / "never"
    data = GeneratorDataset(_config(tmp_path), [str(out)], scenes=3, color=False)
    samples = list(data)
    assert [_key(s) for s in samples] == [(s, k) for s in range(3) for k in range(3)]
    assert "colors" not in samples[0] and samples[0]["depth"].dtype == np.float32
    assert not out.exists()  # writers dropped
    # scenes differ (the box is drawn per scene), keypoints of one scene share the scene
    assert samples[0]["object_states"][1]["local2world"] != samples[3]["object_states"][1]["local2world"]
    assert samples[0]["object_states"] == samples[2]["object_states"]
    # the same seed again: the same samples; another seed: other scenes
    again = list(GeneratorDataset(_config(tmp_path), [str(out)], scenes=3, color=False))
    for a, b in zip(samples, again):
        _assert_equal(a, b, LABELS)
    other = GeneratorDataset(_config(tmp_path), [str(out)], scenes=1, color=False, seed=4).scene_samples(0)
    assert other[0]["object_states"][1]["local2world"] != samples[0]["object_states"][1]["local2world"]


def test_scenes_equal_hybridgen_run_and_labels_only_equals_color_labels(gl_context, tmp_path):
    """Scene s of the generator is scene s of a sharded `hybridgen run` (same SeedSequence spawn)."""
    config = _config(tmp_path, scenes=2)
    hg.run_config(config, [str(tmp_path / "run")])
    written = KeypointDataset(tmp_path / "run")
    color = GeneratorDataset(config, [str(tmp_path / "x")], color=True, first_scene=1, scenes=1)
    labels = GeneratorDataset(config, [str(tmp_path / "x")], color=False, first_scene=1, scenes=1)
    color_samples, label_samples = list(color), list(labels)
    assert [_key(s) for s in color_samples] == [(1, 0), (1, 1), (1, 2)]
    for index, (with_color, labels_only) in enumerate(zip(color_samples, label_samples)):
        stored = written[3 + index]
        _assert_equal(with_color, stored, LABELS + ("colors", "instance_attribute_maps", "object_records",
                                                    "object_states"))
        _assert_equal(labels_only, stored, LABELS + ("instance_attribute_maps", "object_records"))


def test_write_runs_the_writers_as_work_units(gl_context, tmp_path):
    out = tmp_path / "written"
    samples = list(GeneratorDataset(_config(tmp_path), [str(out)], scenes=2, color=False, write=True,
                                    keys=["depth"]))
    assert sorted(samples[0]) == ["depth", "keypoint_index", "scene_index"]
    shards = sorted(p.name for p in (out / "shards").glob("*.hdf5"))
    assert shards == ["scene_000000_chunk_00000.hdf5", "scene_000001_chunk_00000.hdf5"]
    import h5py

    with h5py.File(out / "shards/scene_000001_chunk_00000.hdf5") as h5:
        np.testing.assert_array_equal(h5["depth"][2], samples[5]["depth"])


def test_bad_arguments_are_clear(gl_context, tmp_path):
    with pytest.raises(InputError, match=r"no key\(s\) \['colours'\]"):
        next(iter(GeneratorDataset(_config(tmp_path), [str(tmp_path)], keys=["colours"], color=False)))
    with pytest.raises(InputError, match="worker must be in 0..1"):
        next(GeneratorDataset(_config(tmp_path), [str(tmp_path)]).samples(2, 2))


def test_dataloader_workers_give_the_same_samples(gl_context, tmp_path):
    """Two spawned DataLoader workers render disjoint scenes; sorted, the samples equal the in-process ones."""
    torch = pytest.importorskip("torch")
    from hybridgen.data import TorchGeneratorDataset

    config = _config(tmp_path)
    keys = ["depth", "instance_segmaps", "instance_attribute_maps", "cam2world"]
    data = TorchGeneratorDataset(config, [str(tmp_path / "never")], scenes=3, color=False, keys=keys)
    assert isinstance(data, torch.utils.data.IterableDataset)
    expected = list(data)  # no worker: canonical (scene, keypoint) order
    loader = torch.utils.data.DataLoader(data, batch_size=None, num_workers=2, multiprocessing_context="spawn")
    got = list(loader)
    assert len(got) == len(expected) == 9
    # worker 0 renders scenes 0 and 2, worker 1 scene 1; the loader alternates between workers
    assert [_key(s) for s in got[:2]] == [(0, 0), (1, 0)]
    for a, b in zip(sorted(got, key=_key), expected):
        _assert_equal(a, b, keys)
    assert not (tmp_path / "never").exists()


def test_forked_workers_of_a_rendering_parent_get_a_clear_error(gl_context, tmp_path):
    """This test process holds a GL context (the gl_context fixture): a forked worker could not render (it
    would hang in Mesa), so it stops with the fix instead."""
    torch = pytest.importorskip("torch")
    from hybridgen.data import TorchGeneratorDataset
    from hybridgen.errors import SystemSetupError

    data = TorchGeneratorDataset(_config(tmp_path), [str(tmp_path / "never")], scenes=2, color=False)
    loader = torch.utils.data.DataLoader(data, batch_size=None, num_workers=1, multiprocessing_context="fork")
    with pytest.raises(SystemSetupError, match="multiprocessing_context='spawn'"):
        next(iter(loader))
