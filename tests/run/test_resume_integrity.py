"""Resume trusts only verified outputs of the same config: fingerprints, digests, damaged and missing shards,
the index's sources, and the non-sharded file."""
from __future__ import annotations

import hashlib
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.errors import InputError
from hybridgen.io.integrity import DIGEST_ATTR, verify
from hybridgen.run.shard_index import check_index_sources
from tests.run.scene_configs import LABELS_WITHOUT_NORMALS, floor_and_object

CONFIG = floor_and_object(initializer="seed: SEED, number_of_scenes: 2, keypoints_per_chunk: 2", shape="cube",
                          name="box", width=16, height=12, keypoints=3, renderer=LABELS_WITHOUT_NORMALS)
SINGLE = CONFIG.replace("number_of_scenes: 2, keypoints_per_chunk: 2", "number_of_scenes: 1")


def _digests(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith(".")}


@pytest.fixture
def reference(gl_context, tmp_path, write_config, run_cli):
    """A complete sharded run (seed 1) and its file digests."""
    config = write_config(CONFIG.replace("SEED", "1"))
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 0, err
    return config, out, _digests(out)


def test_every_shard_and_the_index_verify(reference):
    _, out, digests = reference
    assert len(digests) == 5  # 2 scenes x 2 chunks + index
    for name in digests:
        assert verify(out / name) is None
    with h5py.File(out / "shards/scene_000000_chunk_00000.hdf5") as h5:
        assert '"config:main.Initializer#0.seed":"1"' in h5.attrs["fingerprint"]
        assert len(h5.attrs[DIGEST_ATTR]) == 64
    check_index_sources(out / "data.hdf5", deep=True)


def test_changed_config_is_refused_naming_the_key(reference, write_config, run_cli):
    _, out, digests = reference
    changed = write_config(CONFIG.replace("SEED", "2"), "changed.yaml")
    code, _, err = run_cli("run", "-q", str(changed), str(out))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "main.Initializer#0.seed" in err and "--restart" in err and "--force-resume" in err
    assert _digests(out) == digests  # nothing touched
    code, _, err = run_cli("run", "-q", "--restart", str(changed), str(out))
    assert code == 0, err
    with h5py.File(out / "data.hdf5") as h5:
        assert h5.attrs["seed"] == 2
        assert all(h5py.File(out / "shards" / p.name).attrs["seed"] == 2 for p in (out / "shards").glob("*.hdf5"))


def test_force_resume_keeps_intact_shards_of_another_config(reference, write_config, run_cli):
    _, out, digests = reference
    changed = write_config(CONFIG.replace("SEED", "2"), "changed.yaml")
    (out / "shards/scene_000001_chunk_00001.hdf5").unlink()
    code, _, err = run_cli("run", "-q", "--force-resume", str(changed), str(out))
    assert code == 0, err
    with h5py.File(out / "shards/scene_000001_chunk_00001.hdf5") as h5:
        assert h5.attrs["seed"] == 2  # the missing one was rendered with the new config
    assert _digests(out)["shards/scene_000000_chunk_00000.hdf5"] == digests["shards/scene_000000_chunk_00000.hdf5"]


def _flip_bit_in_depth(path: Path) -> None:
    """Flip a bit in the first stored chunk of depth (or of another chunked label pass)."""
    with h5py.File(path, "r") as h5:
        key = "depth" if "depth" in h5 else next(k for k in sorted(h5) if h5[k].chunks is not None)
        offset = h5[key].id.get_chunk_info(0).byte_offset
    data = bytearray(path.read_bytes())
    data[offset + 5] ^= 0x10
    path.write_bytes(bytes(data))


def _flip_bit_in_cam2world(path: Path) -> None:
    with h5py.File(path, "r") as h5:
        offset = h5["cam2world"].id.get_offset()
    data = bytearray(path.read_bytes())
    data[offset + 3] ^= 0x01  # low mantissa bits of the first element: still a plausible matrix
    path.write_bytes(bytes(data))


def _edit_dataset_attribute(path: Path) -> None:
    """Change one attribute of a stored pass (an encoding attribute says how its bytes decode)."""
    with h5py.File(path, "r+") as h5:
        key = next(k for k in sorted(h5) if isinstance(h5[k], h5py.Dataset) and len(h5[k].attrs))
        name = sorted(h5[key].attrs)[0]
        value = h5[key].attrs[name]
        h5[key].attrs[name] = value + 1 if isinstance(value, (int, float, np.number)) else f"{value}x"


@pytest.mark.parametrize("damage", ["depth_bit", "cam2world_bit", "dataset_attribute", "truncate", "empty", "delete",
                                    "garbage"])
def test_damaged_or_missing_shard_is_detected_and_rendered_again(reference, run_cli, damage):
    config, out, digests = reference
    shard = out / "shards/scene_000001_chunk_00000.hdf5"
    if damage == "depth_bit":
        _flip_bit_in_depth(shard)
    elif damage == "cam2world_bit":
        _flip_bit_in_cam2world(shard)
    elif damage == "dataset_attribute":
        _edit_dataset_attribute(shard)
    elif damage == "truncate":
        shard.write_bytes(shard.read_bytes()[: shard.stat().st_size // 2])
    elif damage == "empty":
        shard.write_bytes(b"")
    elif damage == "delete":
        shard.unlink()
    else:
        shard.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 8)
    if damage != "delete":
        assert verify(shard) is not None
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    if damage != "delete":
        assert "rendering it again" in err
    assert _digests(out) == digests  # re-rendered to the same bytes; the others were reused


def test_index_without_its_shards_is_one_line(reference, tmp_path, run_cli):
    _, out, _ = reference
    moved = tmp_path / "copy"
    moved.mkdir()
    (moved / "data.hdf5").write_bytes((out / "data.hdf5").read_bytes())
    with pytest.raises(InputError, match=r"4 missing \(shards/scene_000000_chunk_00000.hdf5"):
        check_index_sources(moved / "data.hdf5")
    code, _, err = run_cli("extract", str(moved / "data.hdf5"), "--output_dir", str(tmp_path / "x"))
    assert code == 2 and "missing" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()
    # what a careless reader gets past the check cannot pass as data
    with h5py.File(moved / "data.hdf5") as h5:
        assert np.isnan(h5["cam2world"][()]).all()
        for key in ("depth", "instance_segmaps"):
            if key in h5 and h5[key].dtype.kind == "f":
                assert np.isnan(h5[key][0]).all()
            elif key in h5 and h5[key].dtype.kind == "i":
                assert (h5[key][0] == -1).all()


def test_index_over_a_replaced_shard_is_one_line(reference, tmp_path, write_config, run_cli):
    config, out, _ = reference
    other = tmp_path / "other"
    changed = write_config(CONFIG.replace("SEED", "7"), "changed.yaml")
    assert run_cli("run", "-q", str(changed), str(other))[0] == 0
    name = "shards/scene_000001_chunk_00001.hdf5"
    (out / name).write_bytes((other / name).read_bytes())  # intact, but not the file the index was built over
    with pytest.raises(InputError, match="not the ones it was built over"):
        check_index_sources(out / "data.hdf5")


def test_damaged_sealed_file_extract_is_one_line_and_writes_nothing(reference, tmp_path, run_cli):
    _, out, _ = reference
    shard = out / "shards/scene_000000_chunk_00000.hdf5"
    _flip_bit_in_depth(shard)
    code, _, err = run_cli("extract", str(shard), "--output_dir", str(tmp_path / "x"))
    assert code == 2 and "damaged" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()


def test_single_file_run_resumes_verifies_and_refuses(gl_context, tmp_path, write_config, run_cli):
    config = write_config(SINGLE.replace("SEED", "1"))
    out = tmp_path / "out"
    assert run_cli("run", "-q", str(config), str(out))[0] == 0
    first = (out / "data.hdf5").read_bytes()
    code, out_text, err = run_cli("run", str(config), str(out))
    assert code == 0 and "nothing to do" in err and "0 keypoint(s)" in out_text
    changed = write_config(SINGLE.replace("SEED", "3"), "changed.yaml")
    code, _, err = run_cli("run", "-q", str(changed), str(out))
    assert code == 2 and "main.Initializer#0.seed" in err
    _flip_bit_in_depth(out / "data.hdf5")
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0 and "rendering it again" in err
    assert (out / "data.hdf5").read_bytes() == first


def test_a_run_resumes_with_another_raster_thread_count(gl_context, tmp_path, write_config, run_cli):
    """render_threads changes how labels are computed, not their values: not part of the fingerprint."""
    config = write_config(SINGLE.replace("SEED", "1"))
    out = tmp_path / "out"
    assert run_cli("run", "-q", str(config), str(out))[0] == 0
    first = (out / "data.hdf5").read_bytes()
    threaded = write_config(SINGLE.replace("SEED", "1").replace("{render_normals: false}",
                                                                 "{render_normals: false, render_threads: 2}"),
                            "threaded.yaml")
    assert "render_threads: 2" in threaded.read_text()
    code, out_text, err = run_cli("run", str(threaded), str(out))
    assert code == 0 and "nothing to do" in err and "0 keypoint(s)" in out_text
    assert (out / "data.hdf5").read_bytes() == first


def test_changed_input_file_is_named(gl_context, tmp_path, write_config, run_cli):
    """Editing the MTL an OBJ names (not named by the config itself) is caught and named."""
    mesh, mtl = tmp_path / "thing.obj", tmp_path / "thing.mtl"
    mtl.write_text("newmtl red\nKd 0.8 0.1 0.1\n")
    mesh.write_text("mtllib thing.mtl\nv 0 0 0.1\nv 1 0 0.1\nv 0 1 0.1\nv 0 0 1\nusemtl red\n"
                    "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n")
    text = SINGLE.replace("SEED", "1").replace(
        "  - name: camera.CameraSampler",
        f"  - name: loader.ObjLoader\n    config: {{path: {mesh}, name: thing, category_id: 3}}\n"
        "  - name: camera.CameraSampler")
    config = write_config(text)
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 0, err
    mtl.write_text("newmtl red\nKd 0.1 0.8 0.1\n")
    code, _, err = run_cli("run", "-q", str(config), str(out))
    # Input files below the config's folder are named relative to it (a moved checkout resumes).
    assert code == 2 and "input:thing.mtl" in err and "input:thing.obj" not in err


def test_fingerprint_does_not_depend_on_where_the_checkout_lies(tmp_path):
    """The same config and assets in two folders give the same fingerprint (and so the same bytes)."""
    from hybridgen.config.config_file import load_config
    from hybridgen.run.fingerprint import run_fingerprint

    prints = []
    for place in ("a", "b/deeper"):
        folder = tmp_path / place
        (folder / "assets").mkdir(parents=True)
        (folder / "assets" / "thing.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n")
        (folder / "assets" / "thing.obj").write_text("mtllib thing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n")
        config = folder / "config.yaml"
        config.write_text(SINGLE.replace("SEED", "1").replace(
            "  - name: camera.CameraSampler",
            "  - name: loader.ObjLoader\n    config: {path: assets/thing.obj, name: thing, category_id: 3}\n"
            "  - name: camera.CameraSampler"))
        prints.append(run_fingerprint(load_config(config, [str(folder / "out")])))
    assert prints[0] == prints[1]
    assert {"input:assets/thing.obj", "input:assets/thing.mtl"} <= set(prints[0])


def test_every_reader_command_on_a_damaged_or_foreign_file_is_one_line(gl_context, tmp_path, write_config, run_cli):
    config = write_config(SINGLE.replace("SEED", "1"))
    out = tmp_path / "out"
    assert run_cli("run", "-q", str(config), str(out))[0] == 0
    damaged = tmp_path / "damaged.hdf5"
    data = bytearray((out / "data.hdf5").read_bytes())
    with h5py.File(out / "data.hdf5") as h5:
        info = h5["depth"].id.get_chunk_info(1)
    data[info.byte_offset:info.byte_offset + info.size] = bytes(info.size)  # a zeroed deflate stream
    damaged.write_bytes(bytes(data))
    foreign = tmp_path / "foreign.hdf5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = np.arange(3)
    garbage = tmp_path / "garbage.hdf5"
    garbage.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 4)
    for path in (damaged, foreign, garbage):
        for argv in (("vis", str(path), "--save", str(tmp_path / "sheets")),
                     ("extract", str(path), "--output_dir", str(tmp_path / "files"))):
            code, _, err = run_cli(*argv)
            assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, (argv, err)
    assert not (tmp_path / "files").exists()
