"""A file that would not change the output never stops a run: a missing ambient map (map_Ka, as pybullet's
jenga.obj names jenga.tga), a missing diffuse map in a labels-only run, a missing diffuse map whose base color
the config overrides. A missing diffuse map that color would show still stops with one line naming it."""
from __future__ import annotations

import h5py
import numpy as np
from PIL import Image

# a 2 m square in the OBJ's XZ plane (Y up: Blender's importer makes it the floor), UV-mapped, material "wood"
SQUARE = """mtllib square.mtl
o Square
v -1 0 1
v 1 0 1
v 1 0 -1
v -1 0 -1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl wood
f 1/1 2/2 3/3
f 1/1 3/3 4/4
"""
CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - {name: main.Initializer, config: {seed: 5}}
  - {name: loader.ObjLoader, config: {path: %s, category_id: 3}}
  - {name: lighting.LightLoader, config: {lights: [{type: SUN, name: sun, energy: 2.0}]}}
  - name: camera.CameraLoader
    config:
      intrinsics: {resolution_x: 24, resolution_y: 16}
      cam_poses: [{location: [0, 0, 1.5], rotation: {format: look_at, value: [0, 0, 0]}}]
%s
  - {name: writer.Hdf5Writer}
"""
LABELS = "  - {name: renderer.SegMapRenderer, config: {map_by: [class, instance]}}"
COLOR = "  - {name: renderer.RgbRenderer, config: {samples: 2, denoise: false, render_depth: true, map_by: [class]}}"
OVERRIDE = ("  - {name: manipulators.MaterialManipulator, config: {selector: {conditions: {name: Square}}, "
            "material: {base_color: [0.2, 0.5, 0.7]}}}\n")


def _scene(folder, mtl: str, texture: bool = False):
    folder.mkdir()
    (folder / "square.obj").write_text(SQUARE)
    (folder / "square.mtl").write_text(mtl)
    if texture:
        Image.fromarray(np.full((4, 4, 3), (200, 60, 30), np.uint8)).save(folder / "wood.png")
    return folder / "square.obj"


def _run(run_cli, write_config, tmp_path, name, mesh, renderer, *flags):
    config = write_config(CONFIG % (mesh, renderer), f"{name}.yaml")
    code, _, err = run_cli("run", "-q", *flags, str(config), str(tmp_path / name))
    return code, err, tmp_path / name / "data.hdf5"


def _read(path):
    with h5py.File(path) as f:
        return {key: f[key][()] for key in f if key in ("colors", "depth", "category_id_segmaps",
                                                          "instance_segmaps")}


def test_a_missing_ambient_map_stops_nothing(gl_context, tmp_path, run_cli, write_config):
    # jenga.obj's case: the MTL names a map_Ka that is not there; nothing renders an ambient map
    plain = _scene(tmp_path / "plain", "newmtl wood\nKd 0.6 0.4 0.2\n")
    ambient = _scene(tmp_path / "ambient", "newmtl wood\nKd 0.6 0.4 0.2\nmap_Ka jenga.tga\nmap_Ks -s 2 2 1 spec.png\n")
    for renderer in (LABELS, COLOR):
        kind = "labels" if renderer is LABELS else "color"
        results = []
        for mesh in (plain, ambient):
            code, err, out = _run(run_cli, write_config, tmp_path, f"{kind}_{mesh.parent.name}", mesh, renderer)
            assert code == 0, err
            results.append(_read(out))
        assert results[0].keys() == results[1].keys() and results[0]
        for key in results[0]:  # the same bytes: the missing maps change no output
            np.testing.assert_array_equal(results[0][key], results[1][key], err_msg=key)
        assert (results[1]["category_id_segmaps"] == 3).all()  # the square fills the view


def test_labels_only_run_with_a_missing_diffuse_map(gl_context, tmp_path, run_cli, write_config):
    textured = _scene(tmp_path / "textured", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n", texture=True)
    missing = _scene(tmp_path / "missing", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n")
    (code_a, err_a, a), (code_b, err_b, b) = (_run(run_cli, write_config, tmp_path, f"labels_{m.parent.name}", m,
                                                   LABELS) for m in (textured, missing))
    assert code_a == 0 and code_b == 0, err_a + err_b
    first, second = _read(a), _read(b)
    for key in ("category_id_segmaps", "instance_segmaps"):
        np.testing.assert_array_equal(first[key], second[key])
        assert (second[key] > 0).all()


def test_color_run_with_a_missing_diffuse_map_stops_with_one_line(gl_context, tmp_path, run_cli, write_config):
    missing = _scene(tmp_path / "missing", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n")
    code, err, out = _run(run_cli, write_config, tmp_path, "color", missing, COLOR)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1, err
    assert str(tmp_path / "missing" / "wood.png") in lines[0] and "--lenient" in lines[0]
    assert "renderer.RgbRenderer" in lines[0] and "Traceback" not in err
    assert not out.exists()
    # --lenient renders it without the texture, with a notice naming the file
    code, err, out = _run(run_cli, write_config, tmp_path, "lenient", missing, COLOR, "--lenient")
    assert code == 0 and "wood.png" in err and out.is_file()


def test_color_run_whose_config_overrides_the_base_color(gl_context, tmp_path, run_cli, write_config):
    # the override replaces the texture: whether it exists changes nothing
    textured = _scene(tmp_path / "textured", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n", texture=True)
    missing = _scene(tmp_path / "missing", "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n")
    images = []
    for mesh in (textured, missing):
        code, err, out = _run(run_cli, write_config, tmp_path, f"over_{mesh.parent.name}", mesh, OVERRIDE + COLOR)
        assert code == 0, err
        images.append(_read(out)["colors"])
    np.testing.assert_array_equal(images[0], images[1])
    assert images[1][0].reshape(-1, 3).mean(axis=0).argmax() == 2  # blue-ish (0.2, 0.5, 0.7), not the texture


def test_the_python_api_stops_on_a_missing_diffuse_map_too(gl_context, tmp_path):
    """hg.render_color (and render_labels with albedo) check the base-color textures themselves: a script that
    calls them (the bproc layer does) gets the same one line as a config run; labels without albedo go on."""
    import pytest

    import hybridgen as hg

    mesh = _scene(tmp_path / "mesh", "newmtl wood\nmap_Kd wood.png\n")
    scene = hg.Scene()
    for obj in hg.load_objects(mesh, category_id=3):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.add_keypoint(hg.look_at([0, -0.5, 1.5], [0, 0, 0]))
    with pytest.raises(hg.InputError, match="wood.png"):
        hg.render_color(scene, [hg.MemorySink()], hg.PathTraceSettings(samples=2))
    with pytest.raises(hg.InputError, match="wood.png"):
        hg.render_labels(scene, [hg.MemorySink()], hg.LabelRequest(albedo=True))
    sink = hg.MemorySink()
    assert hg.render_labels(scene, [sink], hg.LabelRequest(depth=True)) == 1
    assert np.isfinite(sink.frames[0]["depth"]).any()
