""".blend files through the optional bpy venv (hybridgen.io.blend_loader): a scene tools/make_blend_fixture.py
builds with Blender reads back with Blender's names, transforms, Principled values, its image texture, the
light, the world and custom properties. Without bpy, one line says how to get it (this test needs no bpy)."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from hybridgen.errors import SystemSetupError
from hybridgen.io import blend_loader
from tests.conftest import REPO


def _bpy_python() -> Path | None:
    try:
        return blend_loader.bpy_python()
    except SystemSetupError:
        return None


needs_bpy = pytest.mark.skipif(_bpy_python() is None, reason="no Python with bpy (make bpy-venv, or set "
                               "HYBRIDGEN_BPY_PYTHON); .blend loading is an optional extra")


def test_without_bpy_one_line_says_how_to_get_it(tmp_path, monkeypatch):
    blend = tmp_path / "scene.blend"
    blend.write_bytes(b"BLENDER-v402")
    monkeypatch.setenv(blend_loader.BPY_PYTHON_ENV, str(tmp_path / "no-such-python"))
    with pytest.raises(SystemSetupError) as error:
        blend_loader.load_blend(blend)
    line = str(error.value)
    assert "\n" not in line and "make bpy-venv" in line and "HYBRIDGEN_BPY_PYTHON" in line and "bpy==4.2.0" in line


@pytest.fixture(scope="module")
def fixture_blend(tmp_path_factory) -> Path:
    python = _bpy_python()
    if python is None:
        pytest.skip("no Python with bpy")
    out = tmp_path_factory.mktemp("blend") / "scene.blend"
    done = subprocess.run([str(python), str(REPO / "tools" / "make_blend_fixture.py"), str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return out


@needs_bpy
def test_a_blend_scene_reads_as_blender_shows_it(fixture_blend):
    content = blend_loader.load_blend(fixture_blend)
    by_name = {o.name: o for o in content.objects}
    assert sorted(by_name) == ["Box", "Ground"]
    box, ground = by_name["Box"], by_name["Ground"]
    # world vertices: the 2 m cube at (0, 0, 1) turned 0.3 rad about Z; the 10 m plane scaled 1.5
    world = box.vertices @ box.local2world[:3, :3].T + box.local2world[:3, 3]
    np.testing.assert_allclose(world[:, 2].min(), 0.0, atol=1e-6)
    np.testing.assert_allclose(world[:, 2].max(), 2.0, atol=1e-6)
    turned = np.array([[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]])
    corners = {tuple(np.round(p, 5)) for p in world[:, :2]}
    expected = {tuple(np.round(turned @ np.array([x, y]), 5)) for x in (-1, 1) for y in (-1, 1)}
    assert corners == expected
    ground_world = ground.vertices @ ground.local2world[:3, :3].T
    np.testing.assert_allclose(np.abs(ground_world).max(axis=0), [7.5, 7.5, 0.0], atol=1e-6)
    assert len(box.faces) == 12 and len(ground.faces) == 2
    # flat-shaded cube: every corner normal is its face's normal, unit and axis-aligned in the object's frame
    np.testing.assert_allclose(np.abs(box.vertex_normals).max(axis=1), 1.0, atol=1e-6)
    # custom properties, Principled values, the image texture
    assert (box.category_id, ground.category_id) == (7, 1) and box.attributes["label"] == "box"
    assert box.material.name == "Painted" and box.material.roughness == pytest.approx(0.35)
    assert box.material.metallic == pytest.approx(0.2)
    assert Path(box.material.base_color_texture) == fixture_blend.with_name("checker.png")
    assert box.uvs is not None and box.uvs.shape == (36, 2) and 0 <= box.uvs.min() and box.uvs.max() <= 1
    assert ground.material.base_color == pytest.approx((0.2, 0.4, 0.6, 1.0))
    assert ground.material.roughness == pytest.approx(0.8) and ground.material.base_color_texture is None
    # Principled inputs beyond the model's fields: the coat and its own normal map (a Normal Map node on Coat
    # Normal); a sheen input without sheen is left out, a specular tint kept
    assert box.material.extra == {"coat_weight": pytest.approx(0.8), "coat_roughness": pytest.approx(0.2)}
    assert Path(box.material.coat_normal_texture) == fixture_blend.with_name("checker.png")
    assert box.material.normal_texture is None
    assert ground.material.extra == {"specular_tint": pytest.approx((1.0, 0.9, 0.8))}
    # the light, the empty, the world
    (lamp,) = content.lights
    assert (lamp.name, lamp.type, lamp.energy) == ("Lamp", "POINT", pytest.approx(500.0))
    np.testing.assert_allclose(lamp.local2world[:3, 3], [2, -2, 4])
    assert lamp.color == pytest.approx((1.0, 0.9, 0.8))
    np.testing.assert_allclose(content.empties["Target"][:3, 3], [0, 0, 1])
    assert content.world == {"color": pytest.approx((0.1, 0.2, 0.3)), "strength": pytest.approx(0.5),
                             "hdri_path": None}


@needs_bpy
def test_object_types_and_name_pattern(fixture_blend):
    content = blend_loader.load_blend(fixture_blend, obj_types=["mesh"], entities="Gr.*")
    assert [o.name for o in content.objects] == ["Ground"] and not content.lights and not content.empties


CONFIG = """{"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
  {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:1>"}}},
  {"module": "loader.BlendLoader", "config": {"path": "<args:0>", "obj_types": ["mesh", "light"],
                                              "add_properties": {"cp_source": "blend"}}},
  {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": 0.5, "resolution_x": 32, "resolution_y": 24},
     "cam_poses": [{"location": [0, 0, 8], "rotation": {"value": [0, 0, 0]}}]}},
  {"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance", "class"]}},
  {"module": "writer.Hdf5Writer", "config": {}}
]}"""


@needs_bpy
def test_blenderprocs_blend_loader_module(fixture_blend, tmp_path):
    import h5py

    from hybridgen.run.pipeline import run_config

    config = tmp_path / "config.yaml"
    config.write_text(CONFIG)
    run_config(config, [str(fixture_blend), str(tmp_path / "out")])
    with h5py.File(tmp_path / "out" / "0.hdf5") as f:
        segmap = f["segmap"][()]
        states = {o["name"]: o for o in __import__("json").loads(f["object_states"][()])}
    # looking straight down from 8 m: the box's top (2 m high, class 7) in the middle, the ground around it
    assert segmap[12, 16, 1] == 7 and segmap[0, 0, 1] == 1
    assert states["Box"]["source"] == "blend" and states["Box"]["category_id"] == 7


@needs_bpy
def test_subdivision_is_evaluated_at_render_levels_capped_as_blenderproc_renders(tmp_path):
    """A rock with a Subdivision Surface modifier at viewport level 1 and render level 2 (an icosahedron's 20
    triangles -> 60 quads per level 1, x4 per further level, 2 triangles per quad)."""
    import json

    blend = tmp_path / "Rocks_Test_Small.blend"
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"blends": {str(blend): {"objects": ["Rock_Test_Small001"]}}}))
    done = subprocess.run([str(_bpy_python()), str(REPO / "tools" / "make_rock_essentials_standin.py"), str(spec)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]

    def triangles(**options) -> int:
        return len(blend_loader.load_blend(blend, obj_types=["mesh"], **options).objects[0].faces)

    assert triangles() == 20 * 3 * 4 * 2  # render level 2, not the viewport's 1
    assert triangles(render_levels=3) == 20 * 3 * 16 * 2
    assert triangles(render_levels={"Rock_Test_Small001": 5}) == 20 * 3 * 16 * 2  # capped at 3
    assert triangles(render_levels=4, simplify_subdivision_render=0) == 20 * 3 * 64 * 2
