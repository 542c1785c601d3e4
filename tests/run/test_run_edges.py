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
