"""Bad input: one clear line naming file, module and key; exit status 2; no output under a final name."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO

GOOD_MODULES = """
  - name: loader.PrimitiveLoader
    config: {shape: cube, category_id: 1}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 32, resolution_y: 24}
      cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]
  - name: renderer.SegMapRenderer
  - name: writer.Hdf5Writer
"""


def config_text(modules: str = GOOD_MODULES, output: str = '"<args:0>"') -> str:
    return f"global:\n  all:\n    output_dir: {output}\nmodules:\n  - name: main.Initializer\n" + modules


def _replace(old: str, new: str) -> str:
    assert old in GOOD_MODULES
    return config_text(GOOD_MODULES.replace(old, new))


CASES = {
    "malformed_yaml": ("modules: [\n  - name: x\n", [], ["malformed YAML", "line"]),
    "not_a_mapping": ("- a\n- b\n", [], ["a config is a mapping"]),
    "unknown_top_level": ("modulez: []\n", [], ["unknown top-level key", "modules"]),
    "unknown_module": (_replace("loader.PrimitiveLoader", "loader.PrimitivLoader"), ["out"],
                       ["unknown module 'loader.PrimitivLoader'", "did you mean 'loader.PrimitiveLoader'"]),
    "python_import_attempt": (_replace("loader.PrimitiveLoader", "os.system"), ["out"],
                              ["unknown module 'os.system'"]),
    "unknown_key": (_replace("category_id: 1", "categroy_id: 1"), ["out"],
                    ["module 'loader.PrimitiveLoader' (#1)", "key 'categroy_id'", "did you mean 'category_id'"]),
    "wrong_type": (_replace("category_id: 1", "category_id: one"), ["out"],
                   ["module 'loader.PrimitiveLoader' (#1)", "key 'category_id'", "expected int"]),
    "bad_choice": (_replace("shape: cube", "shape: cubee"), ["out"], ["key 'shape'", "did you mean 'cube'"]),
    "missing_args": (config_text(GOOD_MODULES + "  - name: loader.ObjLoader\n    config: {path: '<args:3>'}\n"),
                     [], ["<args:0> at global.all.output_dir", "<args:3> at modules[5].config.path",
                          "0 argument(s)"]),
    "missing_env": (config_text(output='"<env:HYBRIDGEN_TEST_UNSET_VAR>"'), [],
                    ["<env:HYBRIDGEN_TEST_UNSET_VAR>"]),
    "missing_mesh": (config_text(GOOD_MODULES.replace(
        "  - name: camera", "  - name: loader.ObjLoader\n    config: {path: nowhere/duck.obj}\n  - name: camera")),
        ["out"], ["module 'loader.ObjLoader'", "mesh file not found", "duck.obj"]),
    "zero_keypoints": (_replace("cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]",
                                "cam_poses: []"), ["out"], ["camera.CameraLoader", "no camera poses"]),
    "resolution_zero": (_replace("resolution_x: 32", "resolution_x: 0"), ["out"],
                        ["camera.CameraLoader", "intrinsics.resolution_x", "1..16384"]),
    "resolution_absurd": (_replace("resolution_x: 32", "resolution_x: 1000000"), ["out"],
                          ["intrinsics.resolution_x"]),
    "bad_rotation_format": (_replace("format: look_at", "format: lookat"), ["out"],
                            ["cam_poses[0].rotation.format", "did you mean 'look_at'"]),
    "renderer_without_writer": (config_text(GOOD_MODULES.replace("  - name: writer.Hdf5Writer\n", "")), ["out"],
                                ["renderer.SegMapRenderer", "no writer module"]),
    "missing_category": (_replace("category_id: 1", "name: anon"), ["out"], ["no category_id", "'anon'"]),
    "unknown_global_key": (config_text().replace("output_dir:", "output_dri: x\n    output_dir:"), ["out"],
                           ["global.all.output_dri", "did you mean 'output_dir'"]),
    "unsupported_material_parameter": (_replace("category_id: 1", "category_id: 1, material: {shinyness: 1}"),
                                       ["out"], ["loader.PrimitiveLoader", "material.shinyness",
                                                 "unsupported material parameter"]),
    "missing_texture": (config_text(GOOD_MODULES.replace("category_id: 1", "category_id: 1, material: "
                                                         "{base_color_texture: nowhere/wood.png}")
                                    .replace("renderer.SegMapRenderer", "renderer.RgbRenderer\n    config: "
                                             "{samples: 1}")), ["out"],
                        ["renderer.RgbRenderer", "object 'cube'", "texture file not found", "wood.png"]),
    "negative_light_energy": (config_text(GOOD_MODULES.replace(
        "  - name: camera", "  - name: lighting.LightLoader\n    config: {lights: [{type: POINT, energy: -5}]}\n"
        "  - name: camera")), ["out"], ["lighting.LightLoader", "lights[0].energy", ">= 0"]),
    "zero_samples": (config_text(GOOD_MODULES.replace("renderer.SegMapRenderer", "renderer.RgbRenderer\n    config: "
                                                      "{samples: 0}")), ["out"],
                     ["renderer.RgbRenderer", "key 'samples'", "must be > 0"]),
    "setup_pip_missing": ("setup:\n  pip: [surely-not-installed-pkg]\n" + config_text(), ["out"],
                          ["setup.pip", "surely-not-installed-pkg", "pip install"]),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_config_gives_one_clear_line(name, tmp_path, write_config, run_cli, monkeypatch):
    text, args, expected = CASES[name]
    monkeypatch.chdir(tmp_path)
    path = write_config(text)
    code, out, err = run_cli("run", "-q", str(path), *[str(tmp_path / a) for a in args])
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"hybridgen: error: {path}")
    for fragment in expected:
        assert fragment in lines[0], (fragment, lines[0])
    assert "Traceback" not in err
    assert not list(tmp_path.rglob("*.hdf5"))


def _mesh_config(tmp_path: Path, mesh: Path) -> str:
    return config_text(GOOD_MODULES.replace(
        "  - name: camera",
        f"  - name: loader.ObjLoader\n    config: {{path: '{mesh}', category_id: 2}}\n  - name: camera"))


def test_corrupt_mesh(tmp_path, write_config, run_cli):
    mesh = tmp_path / "broken.ply"
    mesh.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 99\n\x00\x01garbage")
    code, _, err = run_cli("run", "-q", str(write_config(_mesh_config(tmp_path, mesh))), str(tmp_path / "out"))
    assert code == 2 and "cannot read mesh" in err and "broken.ply" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.rglob("*.hdf5"))


def test_nan_vertices(tmp_path, write_config, run_cli):
    mesh = tmp_path / "nan.obj"
    mesh.write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    code, _, err = run_cli("run", "-q", str(write_config(_mesh_config(tmp_path, mesh))), str(tmp_path / "out"))
    assert code == 2 and "NaN or inf" in err and "nan.obj" in err
    assert not list(tmp_path.rglob("*.hdf5"))


def test_empty_mesh(tmp_path, write_config, run_cli):
    mesh = tmp_path / "empty.obj"
    mesh.write_text("# nothing\n")
    code, _, err = run_cli("run", "-q", str(write_config(_mesh_config(tmp_path, mesh))), str(tmp_path / "out"))
    assert code == 2 and "no triangles" in err


def test_output_dir_is_a_file(tmp_path, write_config, run_cli):
    blocker = tmp_path / "out"
    blocker.write_text("not a folder")
    code, _, err = run_cli("run", "-q", str(write_config(config_text())), str(blocker))
    assert code == 2 and "is not a directory" in err and "writer.Hdf5Writer" in err
    assert blocker.read_text() == "not a folder"


def test_missing_config_file(tmp_path, run_cli):
    code, _, err = run_cli("run", str(tmp_path / "nope.yaml"))
    assert code == 2 and "config file not found" in err


def test_failure_after_rendering_leaves_no_final_file(tmp_path, write_config, run_cli, monkeypatch):
    """A crash inside the run (after frames were streamed) leaves neither the final nor the temporary file."""
    from hybridgen.errors import InputError
    from hybridgen.modules import hdf5_writer

    def explode(self, context):
        raise InputError("simulated failure while committing")

    monkeypatch.setattr(hdf5_writer.Hdf5Writer, "run", explode)
    code, _, err = run_cli("run", "-q", str(write_config(config_text())), str(tmp_path / "out"))
    assert code == 2 and "simulated failure" in err
    assert list((tmp_path / "out").iterdir()) == []


def test_traceback_only_with_debug(tmp_path, write_config):
    path = write_config(_replace("category_id: 1", "categroy_id: 1"))
    cmd = [sys.executable, "-m", "hybridgen", "run", str(path), str(tmp_path / "o")]
    plain = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO)
    assert plain.returncode == 2 and "Traceback" not in plain.stderr
    debug = subprocess.run([sys.executable, "-m", "hybridgen", "--debug", *cmd[3:]], capture_output=True,
                           text=True, cwd=REPO)
    assert "Traceback" in debug.stderr and "ConfigError" in debug.stderr


def test_config_values_reach_the_scene(tmp_path, write_config):
    """`<args:N>` / `<env:..>` substitution, global.all inheritance and the poses file."""
    from hybridgen.config.config_file import load_config

    poses = tmp_path / "poses.txt"
    poses.write_text("# x y z  tx ty tz\n3 -3 2  0 0 0\n\n-3 3 2 0 0 1  # comment\n")
    text = config_text(GOOD_MODULES.replace(
        "cam_poses: [{location: [3, -3, 2], rotation: {format: look_at, value: [0, 0, 0]}}]",
        "path: '<env:POSES_DIR>/poses.txt'\n      default_cam_param: {rotation: {format: look_at}}"))
    config = load_config(write_config(text), [str(tmp_path / "o")], env={"POSES_DIR": str(tmp_path)})
    assert config.global_all["output_dir"] == str(tmp_path / "o")
    assert config.modules[2].config["path"] == f"{tmp_path}/poses.txt"
    from hybridgen.run.pipeline import build_modules
    from hybridgen.run.context import RunContext

    modules = build_modules(config)
    context = RunContext(config=config)
    modules[2].run(context)
    import hybridgen as hg

    np.testing.assert_allclose(context.scene.camera.keypoints[1], hg.look_at([-3, 3, 2], [0, 0, 1]), atol=1e-12)
    assert modules[4].config["output_dir"] == str(tmp_path / "o")


def test_pose_file_line_errors(tmp_path):
    from hybridgen.config.camera_poses import poses_from_file
    from hybridgen.errors import InputError

    poses = tmp_path / "poses.txt"
    poses.write_text("1 2 3 0 0 0\n1 2 3 0 0\n")
    with pytest.raises(InputError, match=r"poses.txt:2: 5 numbers"):
        poses_from_file(poses, "location rotation/value")


@pytest.mark.parametrize("entry,fragment", [
    ({"location": [0, 0, 1], "cam2world_matrix": np.eye(4).tolist()}, "not both"),
    ({"location": [0, 0]}, "cam_poses[0].location"),
    ({"location": [0, 0, 1], "rotation": {"format": "look_at", "value": [0, 0, 1]}}, "non-zero"),
    ({"cam2world_matrix": np.diag([2, 1, 1, 1]).tolist()}, "rigid"),
    ({"locaton": [0, 0, 1]}, "did you mean 'location'"),
])
def test_pose_entry_errors(entry, fragment):
    from hybridgen.config.camera_poses import pose_from_entry
    from hybridgen.errors import ConfigError

    with pytest.raises(ConfigError, match=None) as info:
        pose_from_entry(entry)
    assert fragment in str(info.value)


def test_pose_entry_formats_agree():
    from hybridgen.config.camera_poses import pose_from_entry
    from hybridgen.scene.frames import look_at_blender, make_pose

    import hybridgen as hg

    target = [0.2, -0.1, 0.4]
    look = pose_from_entry({"location": [1, 2, 3], "rotation": {"format": "look_at", "value": target,
                                                                   "inplane_rot": 0.3}})
    fwd = pose_from_entry({"location": [1, 2, 3], "rotation": {"format": "forward_vec",
                                                                  "value": list(np.subtract(target, [1, 2, 3])),
                                                                  "inplane_rot": 0.3}})
    np.testing.assert_allclose(look, fwd, atol=1e-12)
    blender = make_pose(look_at_blender([1, 2, 3], target, 0.3), [1, 2, 3])
    from_matrix = pose_from_entry({"cam2world_matrix": blender.tolist()})
    np.testing.assert_allclose(from_matrix, look, atol=1e-12)
    cv_matrix = pose_from_entry({"cam2world_matrix": look.tolist(), "source_frame": ["X", "-Y", "-Z"]})
    np.testing.assert_allclose(cv_matrix, look, atol=1e-12)
    from hybridgen.scene.frames import euler_xyz_to_matrix
    angles = [1.1, 0.0, 0.4]
    euler = pose_from_entry({"location": [0, 0, 0], "rotation": {"value": angles}})
    np.testing.assert_allclose(euler[:3, :3], euler_xyz_to_matrix(angles) @ np.diag([1, -1, -1]), atol=1e-12)
    assert hg.look_at([1, 2, 3], target, 0.3) == pytest.approx(look)
