"""Paths a hostile or careless user gives: non-UTF-8 names, NUL, a file where a folder goes, a folder where
a file goes - each one line (exit 2) before anything renders, or a complete run."""
from __future__ import annotations

import os

import h5py
import pytest

from hybridgen.io.integrity import verify

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 3, number_of_scenes: SCENES}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.6, name: box, category_id: 2}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 8, resolution_y: 6}
      cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]
  - name: renderer.SegMapRenderer
    config: {render_normals: false}
  - name: writer.Hdf5Writer
"""


def test_non_utf8_config_and_output_names_run(gl_context, tmp_path, run_cli):
    folder = os.fsencode(tmp_path)
    config = os.fsdecode(folder + b"/conf\xe9.yaml")
    out = os.fsdecode(folder + b"/out\xe9")
    with open(config, "w") as handle:
        handle.write(CONFIG.replace("SCENES", "1"))
    code, _, err = run_cli("run", "-q", config, out)
    assert code == 0, err
    path = os.path.join(out, "data.hdf5")
    assert verify(path) is None
    with h5py.File(path) as h5:
        assert h5.attrs["config_path"].endswith("conf\\xe9.yaml")


def test_nul_in_paths_is_one_line(tmp_path, run_cli):
    code, _, err = run_cli("run", "-q", str(tmp_path / "a\0b.yaml"), str(tmp_path / "out"))
    assert code == 2 and "NUL" in err and len(err.strip().splitlines()) == 1


def test_shards_as_a_file_and_index_as_a_folder_fail_before_rendering(gl_context, tmp_path, write_config, run_cli):
    config = write_config(CONFIG.replace("SCENES", "2"))
    out = tmp_path / "out"
    out.mkdir()
    (out / "shards").write_text("not a folder")
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 2 and "shards' exists and is not a directory" in err
    (out / "shards").unlink()
    (out / "data.hdf5").mkdir()
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 2 and "is a directory" in err
    assert not list((out / "shards").glob("*.hdf5"))  # refused before any unit ran
    single = write_config(CONFIG.replace("SCENES", "1"), "single.yaml")
    code, _, err = run_cli("run", "-q", str(single), str(out))
    assert code == 2 and "is a directory" in err


def test_disk_full_is_one_line_and_leaves_nothing(gl_context, tmp_path, write_config, run_cli, monkeypatch):
    """ENOSPC from the HDF5 layer while committing: one line, no temporary file, no final file."""
    import errno

    import hybridgen.io.hdf5_single as single

    def full(h5, streams=None):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(single, "seal", full)
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", str(write_config(CONFIG.replace("SCENES", "1"))), str(out))
    assert code == 2 and "no space left on the device" in err and len(err.strip().splitlines()) == 1
    assert not [p for p in out.rglob("*") if p.is_file()]


def test_real_full_filesystem(gl_context, tmp_path, write_config, run_cli):
    """The same on a 200 KiB tmpfs (needs permission to mount; skipped otherwise)."""
    import subprocess

    small = tmp_path / "small"
    small.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(small)],
                      capture_output=True).returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    try:
        config = write_config(CONFIG.replace("SCENES", "1").replace(
            "resolution_x: 8, resolution_y: 6", "resolution_x: 256, resolution_y: 192").replace(
            "  - name: writer.Hdf5Writer", "  - name: writer.Hdf5Writer\n    config: {compression: none}"))
        code, _, err = run_cli("run", "-q", str(config), str(small / "out"))
        assert code == 2 and "no space left on the device" in err and len(err.strip().splitlines()) == 1
        assert not [p for p in (small / "out").rglob("*") if p.is_file()]
    finally:
        subprocess.run(["umount", str(small)], check=True)
