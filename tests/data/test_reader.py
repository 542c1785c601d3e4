"""hybridgen.data.KeypointDataset: every pass round-trips against what was rendered, in all three layouts
(single file, sharded virtual index, BlenderProc <i>.hdf5), in the documented dtypes; missing shards are one
clear error; two DataLoader workers read disjoint keypoints."""
from __future__ import annotations

import os
import pickle
from pathlib import Path

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.data import GeneratorDataset, KeypointDataset
from hybridgen.errors import InputError
from tests.data.scenes import config_text

# README output table: key -> (dtype, per-keypoint shape for a 40x30 image)
DOCUMENTED = {
    "colors": (np.uint8, (30, 40, 3)), "depth": (np.float32, (30, 40)), "distance": (np.float32, (30, 40)),
    "normals": (np.float32, (30, 40, 3)), "instance_segmaps": (np.int32, (30, 40)),
    "category_id_segmaps": (np.int32, (30, 40)), "part_segmaps": (np.int32, (30, 40)),
    "albedo": (np.float32, (30, 40, 3)), "forward_flow": (np.float32, (30, 40, 2)),
    "backward_flow": (np.float32, (30, 40, 2)), "forward_flow_occluded": (np.uint8, (30, 40)),
    "backward_flow_occluded": (np.uint8, (30, 40)), "nocs": (np.float32, (30, 40, 3)),
    "cam_K": (np.float64, (3, 3)), "cam2world": (np.float64, (4, 4)),
}
JSON_KEYS = ("instance_attribute_maps", "object_records", "object_states", "light_states")


def _run(tmp_path: Path, name: str, **options) -> tuple[Path, Path]:
    config = tmp_path / f"{name}.yaml"
    config.write_text(config_text(**options))
    out = tmp_path / name
    hg.run_config(config, [str(out)])
    return config, out


def _assert_same_sample(got: dict, expected: dict, *, normals_atol: float = 2e-4) -> None:
    """Exact, but for normals: the single file may store them as octahedral codes (error < 1e-4 rad)."""
    for key, (dtype, shape) in DOCUMENTED.items():
        assert got[key].dtype == dtype and got[key].shape == shape, (key, got[key].dtype, got[key].shape)
        if key == "normals":
            np.testing.assert_allclose(got[key], expected[key], atol=normals_atol, err_msg=key)
        elif key == "cam2world":
            np.testing.assert_allclose(got[key], expected[key], atol=1e-12, err_msg=key)
        else:
            np.testing.assert_array_equal(got[key], expected[key], err_msg=key)
    for key in JSON_KEYS:
        assert got[key] == expected[key], key
    assert (got["scene_index"], got["keypoint_index"]) == (expected["scene_index"], expected["keypoint_index"])


@pytest.fixture(scope="module")
def outputs(tmp_path_factory, gl_context):
    tmp = tmp_path_factory.mktemp("reader")
    single_config, single = _run(tmp, "single")
    _, blenderproc = _run(tmp, "bp", layout="blenderproc", space="world")
    sharded_config, sharded = _run(tmp, "sharded", scenes=2, chunk=2)
    rendered = GeneratorDataset(single_config, [str(tmp / "unused")]).scene_samples(0)
    rendered_sharded = [GeneratorDataset(sharded_config, [str(tmp / "unused")]).scene_samples(s) for s in (0, 1)]
    return {"single": single, "bp": blenderproc, "sharded": sharded, "rendered": rendered,
            "rendered_sharded": rendered_sharded[0] + rendered_sharded[1]}


def test_single_file_round_trip(outputs):
    data = KeypointDataset(outputs["single"])
    assert len(data) == 3 and not data.sharded
    for index, expected in enumerate(outputs["rendered"]):
        _assert_same_sample(data[index], expected)
    # what is visible is decoded: names, categories and the custom attribute of the map_by key
    visible = {o["name"]: o for o in data[0]["instance_attribute_maps"]}
    assert visible["box"]["category_id"] == 2 and visible["box"]["part"] == 9
    assert [o["name"] for o in data[0]["object_states"]] == ["floor", "box", "ball"]
    assert data[0]["light_states"][0]["name"] == "lamp"
    assert isinstance(data.attributes["config"], str) and data.attributes["seed"] == 3
    # the values are those of the file, read directly
    with h5py.File(outputs["single"] / "data.hdf5") as h5:
        np.testing.assert_array_equal(data[2]["depth"], h5["depth"][2])


def test_blenderproc_layout_decodes_to_the_same_conventions(outputs):
    """Normals were written from world-space normals, encoded 0.5n+0.5 in Blender camera axes; the reader
    gives world normals back, and cam2world in OpenCV axes from cam_states."""
    data = KeypointDataset(outputs["bp"])
    assert len(data) == 3
    for index in range(3):
        sample = data[index]
        expected = dict(outputs["rendered"][index])
        # the single-file run wrote camera normals; rotate them to world axes with the pose
        rotation = expected["cam2world"][:3, :3]
        expected["normals"] = (expected["normals"] @ rotation.T).astype(np.float32)
        _assert_same_sample(sample, expected, normals_atol=2e-6)
        assert sample["cam_states"]["cam_K"] == expected["cam_K"].tolist()
    assert data[-1]["keypoint_index"] == 2


def test_sharded_index_round_trip_and_selection(outputs):
    data = KeypointDataset(outputs["sharded"], keys=["depth", "colors", "object_states", "nocs"])
    assert len(data) == 6 and data.sharded
    for index, expected in enumerate(outputs["rendered_sharded"]):
        sample = data[index]
        assert sorted(sample) == ["colors", "depth", "keypoint_index", "nocs", "object_states", "scene_index"]
        for key in ("depth", "colors", "nocs"):
            np.testing.assert_array_equal(sample[key], expected[key])
        assert sample["object_states"] == expected["object_states"]
        assert (sample["scene_index"], sample["keypoint_index"]) == (index // 3, index % 3)
    # the two scenes differ (the box is drawn per scene)
    assert data[0]["object_states"][1]["local2world"] != data[3]["object_states"][1]["local2world"]
    full = KeypointDataset(outputs["sharded"])
    for index, expected in enumerate(outputs["rendered_sharded"]):
        _assert_same_sample(full[index], expected)
    with pytest.raises(InputError, match=r"no key\(s\) \['dpeth'\]; available: \[.*'depth'"):
        KeypointDataset(outputs["sharded"], keys=["dpeth"])
    with pytest.raises(IndexError):
        data[6]
    np.testing.assert_array_equal(data[-1]["depth"], data[5]["depth"])


def test_missing_shards_are_one_clear_error(outputs, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(outputs["sharded"], copy)
    data = KeypointDataset(copy)  # opened while complete, then shards disappear
    (copy / "shards/scene_000001_chunk_00000.hdf5").unlink()
    (copy / "shards/scene_000000_chunk_00001.hdf5").unlink()
    with pytest.raises(InputError) as caught:
        KeypointDataset(copy)
    message = str(caught.value)
    assert "2 missing" in message and "shards/scene_000000_chunk_00001.hdf5" in message \
        and "shards/scene_000001_chunk_00000.hdf5" in message and str(copy / "data.hdf5") in message
    assert "\n" not in message
    with pytest.raises(InputError, match="missing"):  # a worker process opens its own handle: checked there too
        pickle.loads(pickle.dumps(data))[0]


def test_pickles_without_open_files(outputs):
    data = KeypointDataset(outputs["single"], keys=["depth"])
    first = data[0]["depth"]
    assert data._handle is not None
    clone = pickle.loads(pickle.dumps(data))
    assert clone._handle is None
    np.testing.assert_array_equal(clone[0]["depth"], first)


def _tagged(source, keys):
    """A TorchKeypointDataset whose samples also record the process that read them (workers fork)."""
    from hybridgen.data import TorchKeypointDataset

    class Tagged(TorchKeypointDataset):
        def __getitem__(self, index):
            return {**super().__getitem__(index), "pid": os.getpid(), "index": index}

    return Tagged(source, keys=keys)


@pytest.mark.parametrize("layout", ["single", "sharded", "bp"])
def test_two_dataloader_workers_read_disjoint_keypoints(outputs, layout):
    torch = pytest.importorskip("torch")
    from hybridgen.data import TorchKeypointDataset, collate_keypoints

    keys = ["depth", "instance_segmaps", "instance_attribute_maps"]
    data = TorchKeypointDataset(outputs[layout], keys=keys)
    assert isinstance(data, torch.utils.data.Dataset)
    reference = [data[i] for i in range(len(data))]
    tagged = _tagged(outputs[layout], keys)
    tagged[0]  # the parent has the file open before the workers fork: each worker must open its own
    loader = torch.utils.data.DataLoader(tagged, batch_size=2, num_workers=2, collate_fn=collate_keypoints)
    batches = list(loader)
    by_pid: dict[int, set[int]] = {}
    for batch in batches:
        assert batch["depth"].dtype == torch.float32 and batch["depth"].shape[1:] == (30, 40)
        assert isinstance(batch["instance_attribute_maps"], list)  # varying-length JSON stays a list
        for row, index in enumerate(batch["index"].tolist()):
            by_pid.setdefault(batch["pid"][row].item(), set()).add(index)
            np.testing.assert_array_equal(batch["depth"][row].numpy(), reference[index]["depth"])
            np.testing.assert_array_equal(batch["instance_segmaps"][row].numpy(), reference[index]["instance_segmaps"])
            assert batch["instance_attribute_maps"][row] == reference[index]["instance_attribute_maps"]
    assert len(by_pid) == 2 and os.getpid() not in by_pid
    first, second = by_pid.values()
    assert not first & second and first | second == set(range(len(data)))


def test_importing_hybridgen_data_does_not_import_torch():
    import subprocess
    import sys

    code = "import sys, hybridgen.data; assert 'torch' not in sys.modules; print('ok')"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr
