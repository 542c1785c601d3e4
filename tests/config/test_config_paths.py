"""Relative paths in configs: from the working directory (BlenderProc's rule), else from the config's folder;
an error names both places tried (docs/conventions.md section 5)."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import trimesh

from hybridgen.config.config_file import load_config
from hybridgen.errors import ConfigError
from hybridgen.run.pipeline import build_modules
from tests.conftest import REPO

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 3}
  - name: loader.ObjLoader
    config: {path: assets/block.ply, name: block, category_id: 2}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24, fov: 0.8}
      cam_poses: [{location: [0, 0, 5], rotation: {format: look_at, value: [0, 0, 0]}}]
  - name: renderer.SegMapRenderer
    config: {map_by: [class], render_depth: true}
  - name: writer.Hdf5Writer
"""


def _block(path: Path, size: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=[size, size, size]).export(path)


def _depth_at_centre(out: Path) -> float:
    with h5py.File(out / "data.hdf5") as f:
        depth = f["depth"][0]
    return float(depth[12, 16])


def test_config_runs_from_another_working_directory(gl_context, tmp_path, run_cli, monkeypatch):
    project = tmp_path / "project"
    _block(project / "assets" / "block.ply", 1.0)
    (project / "scene.yaml").write_text(CONFIG)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    code, _, err = run_cli("run", "-q", str(project / "scene.yaml"), "out")
    assert code == 0, err
    # the 1 m cube centred at the origin, seen from 5 m above: its top face at z = 0.5 -> depth 4.5 m
    assert _depth_at_centre(elsewhere / "out") == pytest.approx(4.5, abs=1e-4)


def test_working_directory_wins_as_in_blenderproc(gl_context, tmp_path, run_cli, monkeypatch):
    project = tmp_path / "project"
    _block(project / "assets" / "block.ply", 1.0)
    (project / "scene.yaml").write_text(CONFIG)
    cwd = tmp_path / "cwd"
    _block(cwd / "assets" / "block.ply", 2.0)  # same relative path from the working directory: a 2 m cube
    monkeypatch.chdir(cwd)
    code, _, err = run_cli("run", "-q", str(project / "scene.yaml"), "out")
    assert code == 0, err
    assert _depth_at_centre(cwd / "out") == pytest.approx(4.0, abs=1e-4)


def test_missing_file_names_both_places(tmp_path, run_cli, monkeypatch):
    project = tmp_path / "project"
    project.mkdir()
    (project / "scene.yaml").write_text(CONFIG)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli("run", "-q", str(project / "scene.yaml"), "out")
    assert code == 2
    line = err.strip()
    assert "\n" not in line and "mesh file not found: 'assets/block.ply'" in line
    assert "module 'loader.ObjLoader'" in line
    assert str(tmp_path / "assets" / "block.ply") in line and str(project / "assets" / "block.ply") in line
    assert not (tmp_path / "out" / "data.hdf5").exists()


def test_shipped_configs_resolve_from_any_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("quickstart", "room_color", "camera_sampling", "room_lights", "coco_bop"):
        modules = build_modules(load_config(REPO / "configs" / f"{name}.yaml", ["out"]))
        paths = [Path(m.config["path"]) for m in modules if m.module_name == "loader.ObjLoader"]
        assert paths and all(p.is_file() and p.parent == REPO / "configs" / "assets" for p in paths), name
        # outputs stay relative to the working directory
        assert all(m.config["output_dir"] == "out" for m in modules if "output_dir" in m.config)


def test_path_sampler_globs_beside_the_config(tmp_path, monkeypatch):
    from hybridgen.input_paths import config_folder
    from hybridgen.sampling.registry import DrawContext
    from hybridgen.sampling.samplers import path

    textures = tmp_path / "project" / "textures"
    textures.mkdir(parents=True)
    for name in ("a.png", "b.png"):
        (textures / name).write_bytes(b"x")
    monkeypatch.chdir(tmp_path)
    ctx = DrawContext(np.random.default_rng(0))
    with config_folder(tmp_path / "project" / "scene.yaml"):
        drawn = {path(ctx, "textures/*.png") for _ in range(20)}
        assert drawn == {str(textures / "a.png"), str(textures / "b.png")}
        with pytest.raises(ValueError, match="tried .*textures/\\*.jpg and .*project/textures/\\*.jpg"):
            path(ctx, "textures/*.jpg")
    with pytest.raises(ValueError):  # outside a config run: from the working directory only
        path(ctx, "textures/*.png")


def test_missing_texture_names_both_places(tmp_path, monkeypatch):
    from hybridgen.input_paths import config_folder, not_found

    monkeypatch.chdir(tmp_path)
    assert not_found("texture file", "t/wood.png") == "texture file not found: 't/wood.png'"  # Python API: as given
    with config_folder(tmp_path / "project" / "scene.yaml"):
        message = not_found("texture file", "t/wood.png")
    assert message == (f"texture file not found: 't/wood.png' (tried {tmp_path}/t/wood.png from the working "
                       f"directory and {tmp_path}/project/t/wood.png from the config's folder)")


def test_missing_pose_file_names_both_places(tmp_path, run_cli, monkeypatch):
    project = tmp_path / "project"
    project.mkdir()
    (project / "scene.yaml").write_text(CONFIG.replace("      cam_poses: [{location: [0, 0, 5], rotation: {format: "
                                                       "look_at, value: [0, 0, 0]}}]", "      path: poses/p.txt"))
    _block(project / "assets" / "block.ply", 1.0)
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli("run", "-q", str(project / "scene.yaml"), "out")
    assert code == 2 and "camera pose file not found: 'poses/p.txt'" in err
    assert f"tried {tmp_path}/poses/p.txt from the working directory and {project}/poses/p.txt" in err
    (project / "poses").mkdir()
    (project / "poses" / "p.txt").write_text("0 0 5 0 0 0\n")  # found beside the config
    code, _, err = run_cli("run", "-q", str(project / "scene.yaml"), "out")
    assert code == 0, err
