"""BlenderProc 1.x's Rock Essentials modules: the ground tile's geometry against its analytic form (Blender's plane,
cuts, Displace and Subdivision, see hybridgen.scene.ground_tile), the texture sampler's maps and displacement
(also in a rendered depth image), and the rock loader on stand-in packs written by Blender (needs the bpy venv)."""
from __future__ import annotations

import json
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hybridgen.config.config_file import load_config
from hybridgen.errors import ConfigError, SystemSetupError
from hybridgen.io import blend_loader
from hybridgen.run.pipeline import build_modules, execute
from tests.conftest import REPO

HEADER = """\
    {"version": 3, "modules": [
      {"module": "main.Initializer", "config": {"global": {"output_dir": "%s"}}},
"""


def _run(tmp_path: Path, body: str):
    path = tmp_path / "config.yaml"
    path.write_text(textwrap.dedent(HEADER % tmp_path + body + "\n    ]}\n"))
    loaded = load_config(path, [])
    return execute(loaded, build_modules(loaded))


def _ground(tmp_path: Path, cuts: int = 3, levels: int = 1, scale: str = "[5, 4, 1]") -> str:
    (tmp_path / "shader.blend").write_bytes(b"BLENDER-v402")
    return f"""\
      {{"module": "constructor.RockEssentialsGroundConstructor", "config": {{
        "add_properties": {{"cp_category_id": 2}},
        "tiles": [{{"shader_path": "{tmp_path / 'shader.blend'}", "plane_scale": {scale},
                    "subdivision_cuts": {cuts}, "subdivision_render_levels": {levels}, "tile_name": "Gr_Plane_1"}}]}}}}"""


def test_ground_tile_without_texture_sits_half_its_strength_down(tmp_path):
    context = _run(tmp_path, _ground(tmp_path, cuts=3, levels=2))
    (tile,) = context.scene.objects
    assert tile.name == "Gr_Plane_1" and tile.category_id == 2 and tile.attributes["physics"] is False
    assert tile.material.name == "re_ground_mat" and tile.vertex_normals is None  # flat, as Blender's plane
    n = (3 + 1) * 4 + 1  # 5 x 5 control vertices, two Catmull-Clark levels
    assert len(tile.vertices) == n * n and len(tile.faces) == 2 * (n - 1) ** 2
    np.testing.assert_allclose(tile.world_vertices()[:, 2], -0.5, atol=1e-12)  # bpy 4.2: -0.5 at strength 1
    # the 10 x 8 m outline: straight mid-sides, rounded corners (Blender's "All" boundary smoothing)
    bounds = np.abs(tile.vertices[:, :2]).max(axis=0)
    np.testing.assert_allclose(bounds, [5.0, 4.0], atol=1e-12)
    corner = tile.vertices[np.argmax(tile.vertices[:, 0] + tile.vertices[:, 1])]
    assert 4.5 < corner[0] < 5.0 and 3.6 < corner[1] < 4.0


def _maps(folder: Path, height: int) -> None:
    folder.mkdir(parents=True)
    Image.fromarray(np.full((8, 8), height, np.uint16)).save(folder / "DISP16.tif")
    Image.new("RGB", (8, 8), (200, 100, 50)).save(folder / "COL.jpg")
    Image.new("L", (8, 8), 90).save(folder / "GLOSS.jpg")
    Image.new("RGB", (8, 8), (128, 128, 255)).save(folder / "NRM.jpg")


def _sampler(folder: Path, strength: float, ao: str = "[1, 1, 1, 1]") -> str:
    return f""",
      {{"module": "materials.RockEssentialsTextureSampler", "config": {{
        "selector": {{"provider": "getter.Entity", "conditions": {{"name": "Gr_Plane.*", "type": "MESH"}}}},
        "textures": [{{"path": "{folder}/", "uv_scaling": 3, "displacement_strength": {strength},
                       "ambient_occlusion": {ao},
                       "images": {{"color": "COL.jpg", "roughness": "GLOSS.jpg", "normal": "NRM.jpg",
                                   "displacement": "DISP16.tif"}}}}]}}}}"""


def test_sampler_displaces_by_the_height_image_and_sets_the_maps(tmp_path):
    _maps(tmp_path / "tex", 49151)  # h = 0.75 of 16 bits
    context = _run(tmp_path, _ground(tmp_path) + _sampler(tmp_path / "tex", 0.8))
    (tile,) = context.scene.objects
    np.testing.assert_allclose(tile.world_vertices()[:, 2], (49151 / 65535 - 0.5) * 0.8, atol=1e-9)
    material = tile.material
    assert str(material.base_color_texture).endswith("COL.jpg") and str(material.roughness_texture).endswith("GLOSS.jpg")
    assert str(material.normal_texture).endswith("NRM.jpg") and material.specular_texture is None
    assert tile.uvs.min() == 0.0 and tile.uvs.max() == pytest.approx(3.0)  # uv_scaling


def test_ambient_occlusion_darkens_the_color_in_linear_light(tmp_path):
    _maps(tmp_path / "tex", 32768)
    context = _run(tmp_path, _ground(tmp_path) + _sampler(tmp_path / "tex", 1.0, ao="[0.5, 0.25, 1, 1]"))
    color = np.asarray(context.scene.objects[0].material.base_color_texture)
    decoded = np.array([200, 100, 50]) / 255.0
    linear = np.where(decoded <= 0.04045, decoded / 12.92, ((decoded + 0.055) / 1.055) ** 2.4) * [0.5, 0.25, 1]
    expected = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055) * 255
    np.testing.assert_allclose(color[0, 0], expected, atol=1.0)


def test_displaced_tile_in_rendered_depth(tmp_path):
    """A camera 10 m above the tile, looking down: depth at the image centre = 10 - the displaced height."""
    _maps(tmp_path / "tex", 65535)  # h = 1: +0.5 x strength 2 = +1 m
    body = _ground(tmp_path, cuts=4, levels=1) + _sampler(tmp_path / "tex", 2.0) + f""",
      {{"module": "camera.CameraLoader", "config": {{"cam_poses": [{{"location": [0, 0, 10], "rotation": {{"value": [0, 0, 0]}}}}],
        "intrinsics": {{"resolution_x": 32, "resolution_y": 24}}}}}},
      {{"module": "renderer.SegMapRenderer", "config": {{"map_by": ["instance"]}}}},
      {{"module": "renderer.DepthRenderer", "config": {{}}}},
      {{"module": "writer.Hdf5Writer", "config": {{"output_dir": "{tmp_path / 'out'}"}}}}"""
    _run(tmp_path, body)
    import h5py

    with h5py.File(tmp_path / "out" / "0.hdf5") as f:
        depth = np.asarray(f["depth"])
    assert depth[12, 16] == pytest.approx(9.0, abs=1e-4)


def test_bad_keys_name_the_tile_and_the_key(tmp_path):
    with pytest.raises(ConfigError) as error:
        _run(tmp_path, _ground(tmp_path).replace('"subdivision_cuts"', '"subdivison_cuts"'))
    assert "tiles" in str(error.value) and "subdivison_cuts" in str(error.value)
    with pytest.raises(ConfigError) as error:
        _run(tmp_path, _ground(tmp_path).replace(str(tmp_path / "shader.blend"), str(tmp_path / "none.blend")))
    assert "tiles[0].shader_path" in str(error.value) and "none.blend" in str(error.value)


def _bpy_python() -> Path | None:
    try:
        return blend_loader.bpy_python()
    except SystemSetupError:
        return None


@pytest.mark.skipif(_bpy_python() is None, reason="no Python with bpy (make bpy-venv); .blend loading is an extra")
def test_rock_loader_names_counts_properties_and_render_levels(tmp_path):
    pack = tmp_path / "Rocks_Sea_Large.blend"
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"blends": {str(pack): {"objects": ["Rock_Sea_Large001", "Rock_Sea_Large003"],
                                                       "count": 3}}}))
    done = subprocess.run([str(_bpy_python()), str(REPO / "tools" / "make_rock_essentials_standin.py"), str(spec)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    context = _run(tmp_path, f"""\
      {{"module": "loader.RockEssentialsRockLoader", "config": {{"batches": [
        {{"path": "{pack}", "objects": ["Rock_Sea_Large003", "Rock_Sea_Large001"], "amount": 3, "physics": true,
          "render_levels": 1, "high_detail_mode": true, "scale": [2, 2, 2]}},
        {{"path": "{pack}", "render_levels": 3}}]}}}}""")
    names = [o.name for o in context.scene.objects]
    # batch 0: the named rocks in the file's (name) order, repeated up to amount; batch 1: every rock
    assert names == ["Rock_Sea_Large001_0_0", "Rock_Sea_Large003_0_1", "Rock_Sea_Large001_0_2",
                     "Rock_Sea_Large001_1_0", "Rock_Sea_Large002_1_1", "Rock_Sea_Large003_1_2"]
    first, last = context.scene.objects[0], context.scene.objects[-1]
    assert first.attributes["physics"] is True and first.category_id == 1
    assert first.attributes["01) High Detail Mode"] is True and last.attributes["physics"] is False
    np.testing.assert_allclose(np.linalg.norm(first.local2world[:3, :3], axis=0), [2, 2, 2])
    assert len(first.faces) == 20 * 3 * 2 and len(last.faces) == 20 * 3 * 16 * 2  # render levels 1 and 3
