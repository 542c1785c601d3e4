"""docs/conventions.md section 4: the single-file HDF5 output, read back against the renderer's own values."""
from __future__ import annotations

import hashlib
import json
import threading

import h5py
import numpy as np
import pytest
import yaml

import hybridgen as hg
from hybridgen.io.label_encoding import OCTAHEDRAL_MAX_ERROR_RAD, decode_dataset
from tests.conftest import REPO


def _angles(a, b):
    """Angle (rad) between unit normals; 0 where both are the (0, 0, 0) background, pi where one is."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)  # atan2: well conditioned near 0
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
    one_zero = np.any(a, axis=-1) != np.any(b, axis=-1)  # background in one only: as wrong as can be
    return np.where(one_zero, np.pi, angle)


def _run(tmp_path, run_cli, name="out", *extra):
    out = tmp_path / name
    code, stdout, err = run_cli("run", "-q", str(REPO / "configs/quickstart.yaml"), str(out), *extra)
    assert code == 0, err
    return out / "data.hdf5", stdout


def test_quickstart_file_layout(gl_context, tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(REPO)
    path, stdout = _run(tmp_path, run_cli)
    assert "6 keypoint(s)" in stdout and str(path) in stdout
    with h5py.File(path) as f:
        n, h, w = 6, 240, 320
        expected = {"depth": ("float32", (n, h, w)), "distance": ("float32", (n, h, w)),
                    "normals": ("float32", (n, h, w, 3)), "instance_segmaps": ("int32", (n, h, w)),
                    "category_id_segmaps": ("int32", (n, h, w)), "cam_K": ("float64", (n, 3, 3)),
                    "cam2world": ("float64", (n, 4, 4))}
        for key, (dtype, shape) in expected.items():  # what a reader gets, whatever the storage
            decoded = decode_dataset(f[key])
            assert decoded.dtype == np.dtype(dtype) and decoded.shape == shape, key
        for key in ("depth", "normals", "instance_segmaps"):
            assert f[key].chunks == (1, *f[key].shape[1:]) and f[key].compression == "gzip"
        assert f["instance_attribute_maps"].shape == (n,)
        attrs = dict(f.attrs)
        assert attrs["seed"] == 42 and attrs["hybridgen_version"] == hg.__version__
        assert attrs["normals_space"] == "camera" and np.isinf(attrs["depth_background"])
        config = yaml.safe_load(attrs["config"])
        assert config["global"]["all"]["output_dir"] == str(path.parent)  # resolved, not "<args:0>"
        states = json.loads(f["object_states"][()])
        assert [s["idx"] for s in states] == [1, 2, 3, 4, 5]
        assert [s["category_id"] for s in states] == [1, 2, 3, 4, 5]
        assert states[1]["name"] == "box" and np.array(states[1]["local2world"]).shape == (4, 4)
        np.testing.assert_allclose(np.array(states[1]["local2world"])[:3, 3], [-0.9, 0.4, 0.4])
        visible = json.loads(f["instance_attribute_maps"][0])
        ids = decode_dataset(f["instance_segmaps"], 0)
        assert sorted(r["idx"] for r in visible) == sorted(set(np.unique(ids)) - {0})
        # class map is the instance map through object_states
        lut = np.zeros(6, np.int32)
        for s in states:
            lut[s["idx"]] = s["category_id"]
        np.testing.assert_array_equal(decode_dataset(f["category_id_segmaps"]), lut[decode_dataset(f["instance_segmaps"])])
        # what was written is what the renderer renders for that keypoint
        scene = hg.Scene()
        for s, shape, size in zip(states[:4], ["plane", "cube", "sphere", "torus"], [6.0, 0.8, 0.9, 1.0]):
            scene.add(hg.make_primitive(shape, size, name=s["name"], category_id=s["category_id"],
                                        local2world=np.array(s["local2world"])))
        for obj in hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=5,
                                   local2world=np.array(states[4]["local2world"])):
            scene.add(obj)
        intr = hg.Intrinsics(f["cam_K"][2], w, h)
        fresh = hg.RasterView(scene).render(f["cam2world"][2], ["depth", "normals", "instance_segmaps"],
                                            intrinsics=intr)
        for key in ("depth", "instance_segmaps"):  # exact
            np.testing.assert_array_equal(decode_dataset(f[key], 2), fresh[key])
        assert _angles(decode_dataset(f["normals"], 2), fresh["normals"]).max() < OCTAHEDRAL_MAX_ERROR_RAD
        # distance is depth scaled by the pixel ray length
        rays = np.linalg.norm(intr.pixel_rays(), axis=-1)
        depth, distance = decode_dataset(f["depth"], 2), decode_dataset(f["distance"], 2)
        hit = np.isfinite(depth)
        np.testing.assert_allclose(distance[hit], (depth * rays)[hit], rtol=1e-6)
        assert np.isinf(distance[~hit]).all() and (decode_dataset(f["normals"], 2)[~hit] == 0).all()


def test_same_config_and_seed_give_identical_bytes(gl_context, tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(REPO)
    path, _ = _run(tmp_path, run_cli)
    first = hashlib.sha256(path.read_bytes()).hexdigest()
    path.unlink()
    again, _ = _run(tmp_path, run_cli)
    assert hashlib.sha256(again.read_bytes()).hexdigest() == first


@pytest.mark.parametrize("encoding", ["compact", "plain"])
@pytest.mark.parametrize("compression", ["gzip", "blosc2", "lzf", "none"])
def test_compressions_read_back_identically(gl_context, tmp_path, compression, encoding):
    scene = hg.Scene()
    scene.add(hg.make_primitive("sphere", 1.0, name="s", category_id=4))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 48, 32)
    for loc in ([2, 0, 1], [0, 2, 1], [-2, -1, 0.5]):
        scene.camera.add_keypoint(hg.look_at(loc, [0, 0, 0]))
    request = hg.LabelRequest(distance=True, map_by=["class", "instance"], depth_background=-1.0)
    writer = hg.Hdf5SingleFileWriter(tmp_path / "x.hdf5", compression=compression, encoding=encoding)
    hg.render_labels(scene, [writer], request)
    writer.finalize({"object_states": [o.state() for o in scene.objects]})
    view = hg.RasterView(scene, depth_background=-1.0)
    with h5py.File(tmp_path / "x.hdf5") as f:
        if compression == "blosc2":  # HDF5's Blosc2 filter (hdf5plugin); see tests/io/test_blosc2_output.py
            assert "32026" in f["depth"]._filters
        else:
            assert f["depth"].compression == (None if compression == "none" else compression)
        for i, pose in enumerate(scene.camera.keypoints):
            expected = request.compute(view.render_raw(pose), request.tables(view))
            for key in ("depth", "distance", "instance_segmaps", "category_id_segmaps"):
                np.testing.assert_array_equal(decode_dataset(f[key], i), expected[key])
            if encoding == "plain":
                np.testing.assert_array_equal(f["normals"][i], expected["normals"])
            else:
                assert _angles(decode_dataset(f["normals"], i), expected["normals"]).max() < OCTAHEDRAL_MAX_ERROR_RAD
            assert json.loads(f["instance_attribute_maps"][i]) == expected["instance_attribute_maps"]
        assert (f["depth"][()] == -1.0).any() and (decode_dataset(f["category_id_segmaps"]) == 4).any()
        np.testing.assert_array_equal(f["cam2world"][()], np.stack(scene.camera.keypoints))


def test_incomplete_file_never_has_the_final_name(tmp_path):
    writer = hg.Hdf5SingleFileWriter(tmp_path / "data.hdf5")
    from hybridgen.io.frame_sink import PassLayout

    writer.begin(2, [PassLayout("depth", "float32", (4, 4))], {}, {})
    writer.write(0, {"depth": np.zeros((4, 4), np.float32)})
    writer.end()
    assert not (tmp_path / "data.hdf5").exists()
    assert len(list(tmp_path.iterdir())) == 1  # the hidden temporary file
    writer.abort()
    assert list(tmp_path.iterdir()) == []


def _small_writer(path, **options):
    from hybridgen.io.frame_sink import PassLayout

    writer = hg.Hdf5SingleFileWriter(path, **options)
    writer.begin(4, [PassLayout("depth", "float32", (16, 16)), PassLayout("records", "json", ())], {}, {})
    return writer


def _depth(index):
    return np.random.default_rng(index).random((16, 16), dtype=np.float32)


@pytest.mark.parametrize("compression", ["gzip", "blosc2"])
def test_keypoints_are_stored_in_order_whatever_finishes_first(tmp_path, monkeypatch, compression):
    """Keypoint 0's chunk is made last (its job waits until the others are compressed): the file still holds the
    chunks in keypoint order, byte for byte the file one thread writes."""
    files = {}
    for threads in (1, 3):
        writer = _small_writer(tmp_path / f"{threads}.hdf5", threads=threads, compression=compression)
        if threads == 3:
            made, chunk = threading.Event(), writer._chunk

            def late_first(key, index, value):
                if index == 0:
                    assert made.wait(10)  # keypoints 1 and 2 are compressed before keypoint 0
                elif index == 2:
                    made.set()
                return chunk(key, index, value)
            monkeypatch.setattr(writer, "_chunk", late_first)
        for i in range(4):
            writer.write(i, {"depth": _depth(i), "records": [{"keypoint": i}]})
        writer.finalize()
        files[threads] = (tmp_path / f"{threads}.hdf5").read_bytes()
    assert files[1] == files[3]
    with h5py.File(tmp_path / "3.hdf5") as f:
        for i in range(4):
            np.testing.assert_array_equal(f["depth"][i], _depth(i))
            assert json.loads(f["records"][i]) == [{"keypoint": i}]


def test_writes_block_while_the_writer_is_behind(tmp_path, monkeypatch):
    """At most queue_size + threads keypoints are in flight: the producer waits instead of piling up arrays."""
    writer = _small_writer(tmp_path / "x.hdf5", threads=1, queue_size=1)
    release, chunk = threading.Event(), writer._chunk
    monkeypatch.setattr(writer, "_chunk", lambda *args: (release.wait(10), chunk(*args))[1])
    returned = []
    producer = threading.Thread(target=lambda: [returned.append(writer.write(i, {"depth": _depth(i), "records": []}))
                                                for i in range(4)])
    producer.start()
    producer.join(0.5)
    assert len(returned) == 2  # the third write waits for the first keypoint to be stored
    release.set()
    producer.join(10)
    assert len(returned) == 4
    writer.finalize()
    with h5py.File(tmp_path / "x.hdf5") as f:
        np.testing.assert_array_equal(f["depth"][3], _depth(3))



@pytest.mark.parametrize("dtype", ["<f4", ">f4", "<f8", "<u2", ">i2", "<c8", "<c16"])
def test_shuffled_bytes_are_hdf5s_shuffle_filter_output(tmp_path, dtype):
    """The writer deflates ``shuffled(chunk)`` itself: its bytes must be what HDF5's shuffle filter makes of the
    chunk (read back unfiltered from a file HDF5 shuffled), for the word sizes of the fast path (2, 4, 8 bytes)
    and the strided fallback (16), in either byte order."""
    from hybridgen.io.hdf5_single import shuffled

    rng = np.random.default_rng(7)
    values = rng.normal(0, 1e3, size=(1, 37, 29)) * (1 + 1j if dtype[1] == "c" else 1)
    array = values.astype(dtype)
    with h5py.File(tmp_path / "s.hdf5", "w") as f:
        dset = f.create_dataset("x", data=array, chunks=array.shape, shuffle=True)
        mask, stored = dset.id.read_direct_chunk((0, 0, 0))
    assert mask == 0 and len(stored) == array.nbytes
    assert shuffled(array[0]).tobytes() == stored
    assert bytes(shuffled(array[0])) != array.tobytes()  # the filter did reorder them
