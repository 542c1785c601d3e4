"""``compression: blosc2``: the writer makes the Blosc2 filter's chunks itself (hybridgen/io/blosc2_chunks.py) and
stores them with ``write_direct_chunk``. A plain h5py user with hdf5plugin reads exactly the values of the gzip
file written from the same render; our readers register the filter themselves; bytes are deterministic."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import threading

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.io.blosc2_chunks import Blosc2Chunks
from hybridgen.io.hdf5_filters import BLOSC2_FILTER_ID
from tests.conftest import REPO

pytest.importorskip("blosc2")


def _python(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``code`` in a fresh interpreter (no hdf5plugin imported unless it imports it)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], cwd=REPO, capture_output=True,
                          text=True, timeout=120)


@pytest.fixture(scope="module")
def files(gl_context, tmp_path_factory):
    """One render written twice: gzip (the reference, any reader) and blosc2."""
    folder = tmp_path_factory.mktemp("blosc2")
    scene = hg.Scene()
    scene.add(hg.make_primitive("sphere", 1.0, name="s", category_id=4))
    offset = np.eye(4)
    offset[:3, 3] = [0.9, 0.3, 0.4]
    scene.add(hg.make_primitive("cube", 0.5, name="c", category_id=2, local2world=offset))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 64, 48)
    for loc in ([2, 0, 1], [0, 2, 1], [-2, -1, 0.5]):
        scene.camera.add_keypoint(hg.look_at(loc, [0, 0, 0]))
    request = hg.LabelRequest(depth=True, normals=True, distance=True, map_by=["class", "instance"])
    writers = {c: hg.Hdf5SingleFileWriter(folder / f"{c}.hdf5", compression=c) for c in ("gzip", "blosc2")}
    hg.render_labels(scene, list(writers.values()), request)
    for writer in writers.values():
        writer.finalize({"object_states": [o.state() for o in scene.objects]})
    return folder / "gzip.hdf5", folder / "blosc2.hdf5"


def test_filters_per_pass(files):
    """Depth (byte-shuffled) goes through Blosc2 LZ4, the normal codes and id maps stay gzip; the file says how
    to read it."""
    with h5py.File(files[1]) as f:
        filters = {key: f[key]._filters for key in ("depth", "normals", "instance_segmaps", "category_id_segmaps")}
        assert "hdf5plugin" in f.attrs["filters_needed"]
    assert filters["depth"][str(BLOSC2_FILTER_ID)][4:7] == (1, 1, 1)  # level 1, byte shuffle, LZ4
    assert set(filters["depth"]) == {str(BLOSC2_FILTER_ID)}
    for key in ("normals", "instance_segmaps", "category_id_segmaps"):
        assert set(filters[key]) == {"gzip"}, key
    with h5py.File(files[0]) as f:
        assert "filters_needed" not in f.attrs


def test_plain_h5py_with_hdf5plugin_reads_the_gzip_files_values(files):
    """Every dataset of the blosc2 file, read by h5py after ``import hdf5plugin`` alone, equals the gzip file's
    byte for byte (float32 depth bit-exact, normal codes and ids exact): the gzip file is checked against the
    renderer by tests/io/test_hdf5_output.py."""
    done = _python("""
        import sys
        import h5py, hdf5plugin, numpy as np
        with h5py.File(sys.argv[1]) as a, h5py.File(sys.argv[2]) as b:
            assert sorted(a) == sorted(b), (sorted(a), sorted(b))
            for key in a:
                x, y = np.asarray(a[key][()]), np.asarray(b[key][()])
                assert x.dtype == y.dtype and x.shape == y.shape, key
                assert x.tobytes() == y.tobytes() if x.dtype.kind != "O" else x.tolist() == y.tolist(), key
                assert dict(a[key].attrs) == dict(b[key].attrs), key
        assert "hybridgen" not in sys.modules
        print("ok")
    """, *map(str, files))
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def test_without_hdf5plugin_the_read_fails_naming_no_wrong_values(files):
    """A plain h5py reader without hdf5plugin gets an error for a Blosc2 dataset (never wrong values); the gzip
    id maps of the same file still read."""
    done = _python("""
        import sys
        import h5py
        with h5py.File(sys.argv[1]) as f:
            f["category_id_segmaps"][()]
            try:
                f["depth"][0]
            except OSError as exc:
                print("error:", exc)
            print(f.attrs["filters_needed"])
    """, str(files[1]))
    assert done.returncode == 0, done.stderr
    assert "error:" in done.stdout and "pip install hdf5plugin" in done.stdout


def test_our_readers_register_the_filter(files):
    """hybridgen.data's KeypointDataset and ``hybridgen extract`` read the blosc2 file in a process that never
    imported hdf5plugin or the writer: the same decoded values as the gzip file (depth, distance, ids exact;
    normals from the same codes)."""
    done = _python("""
        import sys, pathlib
        import numpy as np
        from hybridgen.data import KeypointDataset
        assert "hdf5plugin" not in sys.modules
        ref, new = KeypointDataset(sys.argv[1]), KeypointDataset(sys.argv[2])
        assert len(ref) == len(new) == 3
        for i in range(3):
            a, b = ref[i], new[i]
            for key in ("depth", "distance", "normals", "instance_segmaps", "category_id_segmaps"):
                assert a[key].dtype == b[key].dtype, key
                assert np.array_equal(a[key].view(np.uint8), b[key].view(np.uint8)), key
        from hybridgen.cli import main
        out = pathlib.Path(sys.argv[3])
        for name, source in (("new", sys.argv[2]), ("ref", sys.argv[1])):
            assert main(["extract", source, "--output_dir", str(out / name), "--keys", "depth", "normals",
                         "--format", "npy", "-q"]) == 0
        files = {name: {p.name.split("_", 1)[1]: p.read_bytes() for p in (out / name).glob("*.npy")}
                 for name in ("ref", "new")}  # <file stem>_<keypoint>_<key>.npy
        assert len(files["ref"]) == 6 and files["ref"] == files["new"]
        print("ok")
    """, str(files[0]), str(files[1]), str(files[1].parent))
    assert done.returncode == 0 and done.stdout.splitlines()[-1] == "ok", done.stderr + done.stdout


def test_chunks_are_deterministic_across_threads_and_processes():
    """The same array gives the same frame from 8 threads at once and in another process (one Blosc2 thread per
    compression; no lock needed, unlike ISA-L)."""
    rng = np.random.default_rng(3)
    depth = np.where(rng.random((96, 128)) < 0.3, np.inf, rng.normal(5, 1, (96, 128))).astype(np.float32)
    chunks = Blosc2Chunks("lz4", 1, "byte", 4)
    serial = chunks.encode(depth)
    results: list[bytes] = []
    threads = [threading.Thread(target=lambda: results.extend(chunks.encode(depth) for _ in range(20)))
               for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(results) == 160 and set(results) == {serial}
    done = _python("""
        import sys, numpy as np, hashlib
        from hybridgen.io.blosc2_chunks import Blosc2Chunks
        rng = np.random.default_rng(3)
        depth = np.where(rng.random((96, 128)) < 0.3, np.inf, rng.normal(5, 1, (96, 128))).astype(np.float32)
        print(hashlib.sha256(Blosc2Chunks("lz4", 1, "byte", 4).encode(depth)).hexdigest())
    """)
    import hashlib

    assert done.returncode == 0 and done.stdout.strip() == hashlib.sha256(serial).hexdigest(), done.stderr


@pytest.mark.parametrize("codec,level,shuffle", [("lz4", 1, "byte"), ("lz4", 9, "none"), ("lz4hc", 1, "bit"),
                                                 ("zstd", 1, "byte"), ("blosclz", 5, "none")])
def test_every_codec_reads_back_exactly_through_the_filter(tmp_path, codec, level, shuffle):
    """Chunks of each codec and shuffle, stored with write_direct_chunk, read back bit-exactly through HDF5's
    Blosc2 filter (float32 with inf and NaN payloads, uint16 codes, uint8 ids)."""
    rng = np.random.default_rng(5)
    arrays = {"f4": rng.normal(3, 2, (2, 40, 56)).astype(np.float32),
              "u2": rng.integers(0, 65535, (2, 40, 56, 2), dtype=np.uint16),
              "u1": np.repeat(rng.integers(0, 9, (2, 40, 7), dtype=np.uint8), 8, axis=2)}
    arrays["f4"][0, :5] = np.inf
    arrays["f4"][1, 3] = np.frombuffer(np.uint32(0x7FC00123).tobytes(), np.float32)[0]  # a NaN payload
    with h5py.File(tmp_path / "c.hdf5", "w") as f:
        for name, array in arrays.items():
            chunks = Blosc2Chunks(codec, level, shuffle, array.itemsize)
            dset = f.create_dataset(name, shape=array.shape, dtype=array.dtype, chunks=(1, *array.shape[1:]),
                                    **chunks.dataset_options())
            for i in range(len(array)):
                dset.id.write_direct_chunk((i,) + (0,) * (array.ndim - 1), chunks.encode(array[i]))
    with h5py.File(tmp_path / "c.hdf5") as f:
        for name, array in arrays.items():
            assert f[name][()].tobytes() == array.tobytes(), name


@pytest.mark.parametrize("compression", ["gzip", "blosc2"])
def test_staged_parts_merge_to_the_direct_file(gl_context, tmp_path, write_config, run_cli, compression):
    """A labels-only run written in verified parts and merged (chunks copied as stored) gives the bytes of the
    file the writer streams directly (the same config run in process without staging), under either compression."""
    from tests.run.test_staged_resume import CONFIG, direct_bytes

    config = write_config(CONFIG.replace("SEED", "3").replace(
        "{resume_chunk_keypoints: 2}", f"{{resume_chunk_keypoints: 2, compression: {compression}}}"))
    out = tmp_path / "out"
    direct = direct_bytes(config, out)
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert err.count("unit scene_") == 4  # 7 keypoints in parts of 2
    assert (out / "data.hdf5").read_bytes() == direct


def test_blenderproc_layout_refuses_blosc2(tmp_path, write_config, run_cli):
    """BlenderProc's tools read gzip only: the layout says so instead of writing files they cannot open."""
    from tests.run.test_staged_resume import CONFIG

    config = CONFIG.replace("SEED", "4").replace("{resume_chunk_keypoints: 2}",
                                                 "{layout: blenderproc, compression: blosc2}")
    code, _, err = run_cli("run", str(write_config(config)), str(tmp_path / "out"))
    assert code == 2 and "compression" in err and "blenderproc" in err, err
    assert not list((tmp_path / "out").glob("*.hdf5"))


@pytest.mark.parametrize("variable,value", [("BLOSC_CLEVEL", "9"), ("BLOSC_NTHREADS", "4"), ("BLOSC_SHUFFLE", "0")])
def test_environment_overrides_of_the_codec_are_refused(monkeypatch, variable, value):
    """c-blosc2 lets BLOSC_* variables override a context's codec, level, shuffle or threads (other bytes, or
    blocks in the order threads finish): the writer refuses them by name instead of writing such chunks."""
    from hybridgen.errors import InputError

    monkeypatch.setenv(variable, value)
    with pytest.raises(InputError, match=variable):
        Blosc2Chunks("lz4", 1, "byte", 4).encode(np.zeros((8, 8), np.float32))
