"""run/ behaviour the mutation run (tools/mutation) found unchecked: --workers > 1 makes even a one-scene,
unchunked config a sharded run (so it needs the single-layout HDF5 writer, checked before anything renders)."""
from __future__ import annotations

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 1, name: ball, category_id: 1}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 16, resolution_y: 12}
      cam_poses: [{location: [3, 0, 1], rotation: {format: look_at, value: [0, 0, 0]}}]
  - name: renderer.SegMapRenderer
    config: {map_by: [instance]}
  - name: writer.Hdf5Writer
    config: {layout: %s}
"""


def test_workers_make_a_one_scene_run_sharded(gl_context, tmp_path, run_cli, write_config):
    blenderproc = write_config(CONFIG % "blenderproc", "bp.yaml")
    code, _, err = run_cli("run", "-q", str(blenderproc), str(tmp_path / "a"), "--workers", "2")
    assert code == 2 and "--workers" in err and "layout: single" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "a").exists() or not any((tmp_path / "a").rglob("*.hdf5"))
    code, _, err = run_cli("run", "-q", str(blenderproc), str(tmp_path / "b"))  # one process: fine as it is
    assert code == 0, err
    single = write_config(CONFIG % "single", "single.yaml")
    code, _, err = run_cli("run", "-q", str(single), str(tmp_path / "c"), "--workers", "2")
    assert code == 0, err
    assert sorted(p.name for p in (tmp_path / "c/shards").glob("scene_*.hdf5")) == ["scene_000000_chunk_00000.hdf5"]
    assert (tmp_path / "c/data.hdf5").exists()


def test_restart_of_one_shard_removes_only_its_scenes_files(tmp_path):
    """``--restart --shard i/n`` deletes the shards of scenes s with s % n == i and the index, nothing else (a
    mutation run found the scene filter unasserted: inverted, it deleted the other shards' finished work)."""
    from types import SimpleNamespace

    from hybridgen.run.runner import discard_outputs

    shards = tmp_path / "shards"
    shards.mkdir()
    names = [f"scene_{s:06d}_chunk_{c:05d}.hdf5" for s in range(4) for c in range(2)]
    for name in names:
        (shards / name).write_bytes(b"x")
    (tmp_path / "data.hdf5").write_bytes(b"x")
    plan = SimpleNamespace(output_dir=tmp_path, folder="shards", file_name="data.hdf5")
    assert discard_outputs(plan, (1, 2)) == 4 + 1  # scenes 1 and 3, two chunks each, and the index
    assert sorted(p.name for p in shards.iterdir()) == [n for n in names if int(n[6:12]) % 2 == 0]
    assert not (tmp_path / "data.hdf5").exists()
    assert discard_outputs(plan) == 4  # no shard given: every remaining shard
    assert list(shards.iterdir()) == []
