"""Configs written in BlenderProc's own schema (v1.12 ``module:`` form and v1.0 ``name:`` form) run unchanged
and build the scene Blender would. The configs are this project's own, exercising the modules and keys of
BlenderProc's basic, camera_sampling, light_sampling, physics_positioning, material_manipulation and
coco_annotations / semantic_segmentation examples on stand-in inputs made here."""
from __future__ import annotations

import json
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.config.config_file import load_config
from hybridgen.config.notices import set_sink, set_strict
from hybridgen.errors import ConfigError
from hybridgen.run.pipeline import build_modules, execute, run_config
from hybridgen.scene.frames import look_at_blender, make_pose
from tests.blenderproc_files import read_numbered

# A room floor and two boxes as a Y-up modelling tool writes them (Blender's OBJ importer turns them Z-up).
SCENE_OBJ = """mtllib scene.mtl
o Plane
v -4 0 4
v 4 0 4
v 4 0 -4
v -4 0 -4
vn 0 1 0
usemtl floor
f 1//1 2//1 3//1
f 1//1 3//1 4//1
"""
BOX = """v {x0} 0 {z0}
v {x1} 0 {z0}
v {x1} 0 {z1}
v {x0} 0 {z1}
v {x0} {h} {z0}
v {x1} {h} {z0}
v {x1} {h} {z1}
v {x0} {h} {z1}
f -8 -6 -7
f -8 -5 -6
f -4 -3 -2
f -4 -2 -1
f -8 -7 -3
f -8 -3 -4
f -7 -6 -2
f -7 -2 -3
f -6 -5 -1
f -6 -1 -2
f -5 -8 -4
f -5 -4 -1
"""
MTL = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl red\nKd 0.8 0.1 0.1\nnewmtl green\nKd 0.1 0.8 0.1\n"


def write_scene(folder: Path) -> Path:
    """scene.obj: Plane (floor), Cube and Cube.001 (red), Cylinder (green) - several `o` over shared materials."""
    text = SCENE_OBJ
    for name, material, (x0, x1, z0, z1, h) in (("Cube", "red", (-1.5, -0.5, -0.5, 0.5, 1.0)),
                                               ("Cube.001", "red", (0.5, 1.5, -0.5, 0.5, 0.6)),
                                               ("Cylinder", "green", (-0.3, 0.3, 1.0, 1.6, 0.8))):
        text += f"o {name}\nusemtl {material}\n" + BOX.format(x0=x0, x1=x1, z0=z0, z1=z1, h=h)
    (folder / "scene.mtl").write_text(MTL)
    (folder / "scene.obj").write_text(text)
    return folder / "scene.obj"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture()
def notices():
    lines: list[str] = []
    set_sink(lines.append)
    yield lines
    set_sink(None)
    set_strict(False)


BASIC_V3 = """\
    # Args: <cam_file> <obj_file> <output_dir>
    {
      "version": 3,
      "setup": {
        "blender_install_path": "/home_local/<env:HYBRIDGEN_TEST_SURELY_UNSET>/blender/",
        "pip": ["h5py", "pypng==0.0.20"]
      },
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:2>", "max_bounces": 2,
                                                              "transparency_bounces": 2}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:1>",
                                                     "add_properties": {"cp_category_id": "1"}}},
        {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [5, -5, 5],
                                                                  "energy": 1000}]}},
        {"module": "camera.CameraLoader", "config": {"path": "<args:0>", "file_format": "location rotation/value",
                                                     "intrinsics": {"fov": 1, "resolution_x": 48,
                                                                    "resolution_y": 36}}},
        {"module": "renderer.RgbRenderer", "config": {"output_key": "colors", "samples": 2,
                                                      "render_normals": True, "normals_output_key": "normals",
                                                      "render_distance": True, "image_type": "PNG"}},
        {"module": "writer.Hdf5Writer", "config": {"postprocessing_modules": {"distance": [
            {"module": "postprocessing.Dist2Depth"}, {"module": "postprocessing.TrimRedundantChannels"}]}}}
      ]
    }
"""


def test_basic_v3_runs_unchanged_and_the_floor_is_horizontal(tmp_path, notices, monkeypatch):
    monkeypatch.delenv("HYBRIDGEN_TEST_SURELY_UNSET", raising=False)
    obj = write_scene(tmp_path)
    # BlenderProc's camera file: location and Blender XYZ Euler angles; looking down at the floor at 45 deg
    cams = write(tmp_path, "camera_positions", "0 -6 6 0.785398 0 0\n5 -5 5 0.9553 0 0.785398\n")
    config = write(tmp_path, "config.yaml", BASIC_V3)
    out = tmp_path / "out"
    summary = run_config(config, [str(cams), str(obj), str(out)])
    assert summary.frames == 2
    # one notice line each for the Blender setup keys and the Cycles-only global key; none is an error
    assert any("blender_install_path" in n and "ignored" in n for n in notices)
    assert any("transparency_bounces" in n for n in notices)
    # BlenderProc's files: one <i>.hdf5 per keypoint, Dist2Depth's depth (trimmed, its version 1.0.0)
    assert sorted(p.name for p in out.iterdir()) == ["0.hdf5", "1.hdf5"]
    with h5py.File(out / "0.hdf5") as f:
        assert "depth" in f and "distance" not in f  # Dist2Depth: depth instead of distance
        assert f["depth"].shape == (36, 48) and f["depth"].dtype == np.float32
        assert f["depth_version"][()].tolist() == [b"1.0.0"] and f["colors_version"][()].tolist() == [b"2.0.0"]
    from hybridgen.data import KeypointDataset

    samples = list(KeypointDataset(out, keys=["normals", "cam2world", "depth"]))
    normals, cam2world, depth = ([s[k] for s in samples] for k in ("normals", "cam2world", "depth"))
    for i in range(2):
        world = normals[i] @ cam2world[i][:3, :3].T  # camera (OpenCV) -> world axes
        # the pixel at the image centre sees the floor (the boxes stand off-centre)
        centre = world[18, 24]
        np.testing.assert_allclose(centre, [0, 0, 1], atol=2e-3)
        assert np.isfinite(depth[i][18, 24])
    # depth of the centre pixel = the camera's height / cos(view angle) * cos(0): 6 / cos(45 deg) for view 0
    assert depth[0][18, 24] == pytest.approx(np.hypot(6, 6) * np.cos(np.radians(0.0)), rel=0.03)


def test_blender_setup_keys_and_strict(tmp_path, notices, monkeypatch):
    monkeypatch.delenv("HYBRIDGEN_TEST_SURELY_UNSET", raising=False)
    obj = write_scene(tmp_path)
    config = write(tmp_path, "config.yaml", BASIC_V3)
    args = [str(tmp_path / "cams"), str(obj), str(tmp_path / "out")]
    loaded = load_config(config, args)  # an unset <env:...> inside an ignored setup key is no error
    assert [m.name for m in loaded.modules] == ["main.Initializer", "loader.ObjLoader", "lighting.LightLoader",
                                                "camera.CameraLoader", "renderer.RgbRenderer", "writer.Hdf5Writer"]
    assert loaded.global_all == {"output_dir": str(tmp_path / "out"), "max_bounces": 2}
    assert loaded.modules[1].config["category_id"] == 1  # cp_category_id "1" as BlenderProc reads it
    set_strict(True)
    with pytest.raises(ConfigError, match=r"setup.*blender_install_path.*--strict"):
        load_config(config, args)


def test_unset_env_in_a_used_key_is_still_an_error(tmp_path, monkeypatch):
    monkeypatch.delenv("HYBRIDGEN_TEST_SURELY_UNSET", raising=False)
    config = write(tmp_path, "c.yaml", """\
        {"version": 3, "modules": [{"module": "main.Initializer",
                                    "config": {"global": {"output_dir": "<env:HYBRIDGEN_TEST_SURELY_UNSET>"}}}]}
    """)
    with pytest.raises(ConfigError, match="HYBRIDGEN_TEST_SURELY_UNSET"):
        load_config(config)


def test_v1_name_form_with_top_level_global(tmp_path, notices):
    obj = write_scene(tmp_path)
    cams = write(tmp_path, "cams", "0 -6 6 0.785398 0 0\n")
    config = write(tmp_path, "v1.yaml", """\
        {
          "setup": {"blender_install_path": "/opt/blender/", "blender_version": "blender-2.80-linux",
                    "pip": ["h5py", "imageio", "surely-not-a-real-blender-pkg-zz @ git+https://example.org/x"]},
          "global": {"all": {"output_dir": "<args:2>"}, "renderer": {"pixel_aspect_x": 1.333333333}},
          "modules": [
            {"name": "main.Initializer", "config": {}},
            {"name": "loader.ObjLoader", "config": {"path": "<args:1>"}},
            {"name": "camera.CameraLoader", "config": {"path": "<args:0>", "file_format": "location rotation",
                                                       "default_cam_param": {"fov": 1}}},
            {"name": "renderer.NormalRenderer", "config": {"output_key": "normals"}},
            {"name": "writer.Hdf5Writer", "config": {}}
          ]
        }
    """)
    loaded = load_config(config, [str(cams), str(obj), str(tmp_path / "out")])
    names = [m.name for m in loaded.modules]
    # v1.0's renderers set Blender's pixel aspect when they render: a camera.PixelAspect before the renderer
    assert names == ["main.Initializer", "loader.ObjLoader", "camera.CameraLoader", "camera.PixelAspect",
                     "renderer.SegMapRenderer", "writer.Hdf5Writer"]
    normal = loaded.modules[4].config
    assert normal["render_normals"] is True and not normal["render_depth"] and normal["map_by"] is None
    assert loaded.modules[2].config["intrinsics"] == {"fov": 1}  # v1.0 kept fov among the pose defaults
    assert not any("pixel_aspect_x" in n for n in notices)
    assert any("surely-not-a-real-blender-pkg-zz" in n for n in notices)  # a URL requirement: a notice
    modules = build_modules(loaded)
    context = execute(loaded, modules[:4])
    assert [o.name for o in context.scene.objects] == ["Plane", "Cube", "Cube.001", "Cylinder"]
    # Blender, 512 x 512 at pixel aspect 4/3 (sensor fit AUTO spans the width): fx from the 1 rad fov, fy 4/3 fx
    K = context.scene.camera.intrinsics.K
    assert K[0, 0] == pytest.approx(256 / np.tan(0.5), rel=1e-12)
    assert K[1, 1] == pytest.approx(K[0, 0] * 1.333333333, rel=1e-12) and tuple(K[:2, 2]) == (255.5, 255.5)


def test_module_and_name_together_and_unavailable_modules(tmp_path):
    both = write(tmp_path, "both.yaml", '{"version": 3, "modules": [{"module": "main.Initializer", '
                 '"name": "loader.ObjLoader"}]}')
    with pytest.raises(ConfigError, match="differ"):
        load_config(both)
    blend = write(tmp_path, "blend.yaml", '{"version": 3, "modules": [{"module": "loader.BlendLoader", '
                  '"config": {"path": "x.blend"}}]}')
    assert [m.name for m in load_config(blend).modules] == ["loader.BlendLoader"]  # read through bpy (io/blend_loader)
    suncg = write(tmp_path, "suncg.yaml", '{"modules": [{"name": "loader.SuncgLoader", "config": {}}]}')
    with pytest.raises(ConfigError, match="withdrawn"):
        load_config(suncg)


PHYSICS_V3 = """\
    {
      "version": 3,
      "setup": {"blender_install_path": "/opt/blender/"},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:2>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:0>"}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:1>"}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Ball.*", "type": "MESH"}},
            "cp_physics": True, "cp_category_id": 2}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Ground"}},
            "cp_physics": False, "cp_category_id": 1}},
        {"module": "object.ObjectPoseSampler", "config": {
            "objects_to_sample": {"provider": "getter.Entity", "conditions": {"cp_physics": True}},
            "pos_sampler": {"provider": "sampler.Uniform3d", "max": [-0.6, -0.6, 0.8], "min": [0.6, 0.6, 0.3]},
            "rot_sampler": {"provider": "sampler.Uniform3d", "min": [0, 0, 0], "max": [6.28, 6.28, 6.28]}}},
        {"module": "object.PhysicsPositioning", "config": {
            "min_simulation_time": 1, "max_simulation_time": 6, "check_object_interval": 0.5,
            "solver_iters": 20, "substeps_per_frame": 10, "collision_shape": "CONVEX_HULL"}}
      ]
    }
"""


def _icosphere_obj(names: list[str], materials: list[str], spacing: float) -> str:
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=1, radius=0.1)
    lines, offset = ["mtllib balls.mtl"], 0
    for i, (name, material) in enumerate(zip(names, materials)):
        lines += [f"o {name}", f"usemtl {material}"]
        lines += [f"v {x + i * spacing} {y} {z}" for x, y, z in sphere.vertices]
        lines += [f"f {a + 1 + offset} {b + 1 + offset} {c + 1 + offset}" for a, b, c in sphere.faces]
        offset += len(sphere.vertices)
    return "\n".join(lines) + "\n"


def test_physics_positioning_one_body_per_o_rests_on_a_horizontal_floor(tmp_path, notices):
    pytest.importorskip("pybullet")
    names = ["Ball", "Ball.001", "Ball.002", "Ball.003"]
    (tmp_path / "balls.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n")
    (tmp_path / "active.obj").write_text(_icosphere_obj(names, ["a", "b", "a", "b"], 0.3))
    # the ground as a Y-up tool writes it: y = 0 is the floor, normal +Y
    (tmp_path / "passive.obj").write_text("o Ground\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\nf 1 2 3\nf 1 3 4\n"
                                          "v -3 -0.2 3\nv 3 -0.2 3\nv 3 -0.2 -3\nv -3 -0.2 -3\nf 5 7 6\nf 5 8 7\n"
                                          "f 1 5 6\nf 1 6 2\nf 2 6 7\nf 2 7 3\nf 3 7 8\nf 3 8 4\nf 4 8 5\nf 4 5 1\n")
    config = write(tmp_path, "physics.yaml", PHYSICS_V3)
    loaded = load_config(config, [str(tmp_path / "active.obj"), str(tmp_path / "passive.obj"), str(tmp_path)])
    physics = [m for m in loaded.modules if m.name == "object.PhysicsPositioning"][0].config
    assert physics["solver_iterations"] == 20 and physics["collision_shape"] == "convex_hull"
    assert any("substeps_per_frame" in n for n in notices)
    context = execute(loaded, build_modules(loaded))
    balls = [o for o in context.scene.objects if o.name.startswith("Ball")]
    assert [o.name for o in balls] == names  # one body per `o`, Blender's names, not per material
    assert all(o.attributes["physics"] is True and o.category_id == 2 for o in balls)
    ground = context.scene.by_name("Ground")
    np.testing.assert_allclose(ground.world_vertices()[:, 2].max(), 0.0, atol=1e-9)  # floor at z = 0
    for ball in balls:  # all rest on the floor: lowest point at z ~ 0 (within the contact margin)
        assert ball.world_vertices()[:, 2].min() == pytest.approx(0.0, abs=0.01)


MATERIAL_V3 = """\
    {
      "version": 3,
      "setup": {"blender_install_path": "/opt/blender/"},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:1>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:0>"}},
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Material", "conditions": {"name": "red"}},
            "cf_set_base_color": [0.0, 0.0, 1.0, 1.0], "cf_set_Roughness": 0.2, "cf_set_metallic": 1.0,
            "mode": "once_for_each"}},
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Material", "conditions": {"name": "green"}},
            "cf_switch_to_emission_shader": {"color": [1, 1, 0.5, 1], "strength": 5}}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Cube.001"}},
            "matrix_world": [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]}}
      ]
    }
"""


def test_material_manipulation_selects_by_material_name(tmp_path, notices):
    obj = write_scene(tmp_path)
    config = write(tmp_path, "material.yaml", MATERIAL_V3)
    loaded = load_config(config, [str(obj), str(tmp_path)])
    context = execute(loaded, build_modules(loaded))
    scene = context.scene
    for name in ("Cube", "Cube.001"):
        material = scene.by_name(name).material
        np.testing.assert_allclose(material.base_color, [0, 0, 1, 1])
        assert material.roughness == pytest.approx(0.2) and material.metallic == pytest.approx(1.0)
    np.testing.assert_allclose(scene.by_name("Plane").material.base_color[:3], [0.5, 0.5, 0.5], atol=1 / 255)
    cylinder = scene.by_name("Cylinder").material
    np.testing.assert_allclose(cylinder.emission, [1, 1, 0.5])
    assert cylinder.emission_strength == 5
    moved = scene.by_name("Cube.001").local2world
    np.testing.assert_allclose(moved, [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]], atol=1e-9)


SAMPLING_V3 = """\
    {
      "version": 3,
      "setup": {"blender_install_path": "/opt/blender/"},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:1>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:0>"}},
        {"module": "lighting.LightSampler", "config": {"lights": [{
            "location": {"provider": "sampler.Shell", "center": [1, 2, 3], "radius_min": 4, "radius_max": 7,
                         "elevation_min": 15, "elevation_max": 70, "uniform_elevation": True},
            "color": {"provider": "sampler.Color", "min": [0.5, 0.5, 0.5, 1.0], "max": [1.0, 1.0, 1.0, 1.0]},
            "type": "POINT", "energy": 500}]}},
        {"module": "camera.CameraSampler", "config": {
            "intrinsics": {"fov": 1, "resolution_x": 32, "resolution_y": 24},
            "cam_poses": [{"number_of_samples": 5,
              "location": {"provider": "sampler.Uniform3d", "max": [3, 3, 4], "min": [-3, -3, 6]},
              "rotation": {"format": "look_at", "value": {"provider": "getter.POI"}}}]}}
      ]
    }
"""


def test_camera_and_light_sampling_as_blenderproc_draws(tmp_path, notices):
    obj = write_scene(tmp_path)
    config = write(tmp_path, "sampling.yaml", SAMPLING_V3)
    loaded = load_config(config, [str(obj), str(tmp_path)])
    context = execute(loaded, build_modules(loaded))
    scene = context.scene
    (light,) = scene.lights
    offset = light.local2world[:3, 3] - [1, 2, 3]
    assert 4 <= np.linalg.norm(offset) <= 7
    assert 15 <= np.degrees(np.arcsin(offset[2] / np.linalg.norm(offset))) <= 70
    from hybridgen.sampling.getters import point_of_interest
    from hybridgen.sampling.registry import DrawContext

    poi = point_of_interest(DrawContext(np.random.default_rng(0), scene))
    poses = [scene.camera.keypoints[i] for i in range(len(scene.camera))]
    assert len(poses) == 5
    for cam2world in poses:
        location = cam2world[:3, 3]
        assert -3 <= location[0] <= 3 and -3 <= location[1] <= 3 and 4 <= location[2] <= 6  # min > max: ordered
        view = poi - location  # OpenCV z axis is the view direction
        np.testing.assert_allclose(cam2world[:3, 2], view / np.linalg.norm(view), atol=1e-9)


def test_opencv_source_frame_gives_the_look_at_pose(tmp_path):
    location, target = [2.0, -3.0, 1.5], [0.2, 0.1, 0.3]
    blender = make_pose(look_at_blender(location, target), location)
    opencv = blender @ np.diag([1.0, -1.0, -1.0, 1.0])
    config = write(tmp_path, "pose.yaml", f"""\
        {{"version": 3, "setup": {{"blender_install_path": "/opt/blender/"}},
          "modules": [
            {{"module": "main.Initializer", "config": {{"global": {{"output_dir": "{tmp_path}"}}}}}},
            {{"module": "camera.CameraLoader", "config": {{
                "source_frame": ["X", "-Y", "-Z"],
                "cam_poses": [{{"cam2world_matrix": {opencv.tolist()}}}]}}}},
            {{"module": "camera.CameraLoader", "config": {{
                "cam_poses": [{{"location": {location}, "rotation": {{"format": "look_at", "value": {target}}}}},
                              {{"cam2world_matrix": {blender.tolist()}}}]}}}}
          ]}}
    """)
    loaded = load_config(config)
    camera = execute(loaded, build_modules(loaded)).scene.camera
    from_opencv, from_look_at, from_blender = (camera.keypoints[i] for i in range(3))
    np.testing.assert_allclose(from_opencv, from_look_at, atol=1e-9)
    np.testing.assert_allclose(from_blender, from_look_at, atol=1e-9)
    np.testing.assert_allclose(from_look_at, opencv, atol=1e-9)  # hybridgen keeps OpenCV axes inside


COCO_V3 = """\
    {
      "version": 3,
      "setup": {"blender_install_path": "/opt/blender/", "pip": ["h5py", "scikit-image"]},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:1>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:0>"}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Cube.*"}}, "cp_category_id": 3}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": [{"name": "Plane"}, {"name": "Cylinder"}]},
            "cp_category_id": 7}},
        {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [0, -3, 6],
                                                                  "energy": 800}]}},
        {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": 1.2, "resolution_x": 40,
                                                                    "resolution_y": 30},
            "cam_poses": [{"location": [0, -5, 5], "rotation": {"format": "look_at", "value": [0, 0, 0.3]}}]}},
        {"module": "renderer.RgbRenderer", "config": {"samples": 1, "output_key": "colors"}},
        {"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance", "class", "name"]}},
        {"module": "writer.CocoAnnotationsWriter", "config": {"append_to_existing_output": True}}
      ]
    }
"""


def test_coco_annotations_at_blenderprocs_place(tmp_path, notices):
    obj = write_scene(tmp_path)
    config = write(tmp_path, "coco.yaml", COCO_V3)
    out = tmp_path / "out"
    loaded = load_config(config, [str(obj), str(out)])
    seg = [m for m in loaded.modules if m.name == "renderer.SegMapRenderer"][0].config
    assert seg["render_depth"] is False and seg["render_normals"] is False  # BlenderProc's: segmaps only
    run_config(config, [str(obj), str(out)])
    annotations = out / "coco_data" / "coco_annotations.json"
    assert annotations.is_file()
    from pycocotools.coco import COCO

    coco = COCO(str(annotations))
    categories = {a["category_id"] for a in coco.dataset["annotations"]}
    assert categories <= {3, 7} and 3 in categories
    for ann in coco.dataset["annotations"]:
        mask = coco.annToMask(ann)
        assert mask.sum() == pytest.approx(ann["area"], abs=1)
    # BlenderProc's names: coco_data/rgb_0000.png, file_name relative to output_dir ("coco_data/rgb_0000.png")
    assert [i["file_name"] for i in coco.dataset["images"]] == ["coco_data/rgb_0000.png"]
    assert coco.dataset["images"][0]["id"] == 0
    first = out / "coco_data" / "rgb_0000.png"
    assert first.is_file() and not (out / "coco_data" / "images").exists()
    first_bytes = first.read_bytes()
    n_annotations = len(coco.dataset["annotations"])
    # append_to_existing_output: the numbering continues after the highest image id, as BlenderProc's
    run_config(config, [str(obj), str(out)])
    appended = json.loads(annotations.read_text())
    assert [(i["id"], i["file_name"]) for i in appended["images"]] == [(0, "coco_data/rgb_0000.png"),
                                                                        (1, "coco_data/rgb_0001.png")]
    assert first.read_bytes() == first_bytes and (out / "coco_data" / "rgb_0001.png").is_file()
    assert len(appended["annotations"]) == 2 * n_annotations
    assert {a["image_id"] for a in appended["annotations"][n_annotations:]} == {1}


RENAMED_KEYS_V3 = """\
    {
      "version": 3,
      "setup": {"blender_install_path": "/opt/blender/"},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:1>"}}},
        {"module": "loader.ObjectLoader", "config": {"path": "<args:0>",
                                                     "add_properties": {"cp_category_id": "1"}}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "Cube.*"}}, "cp_category_id": 3}},
        {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [0, -3, 6],
                                                                  "energy": 800}]}},
        {"module": "camera.CameraLoader", "config": {"intrinsics": {"fov": 1.2, "resolution_x": 40,
                                                                    "resolution_y": 30},
            "cam_poses": [{"location": [0, -5, 5], "rotation": {"format": "look_at", "value": [0, 0, 0.3]}},
                          {"location": [3, -4, 4], "rotation": {"format": "look_at", "value": [0, 0, 0.3]}}]}},
        {"module": "renderer.RgbRenderer", "config": {"samples": 1, "render_depth": True,
                                                      "render_normals": True, RGB_KEYS}},
        {"module": "renderer.SegMapRenderer", "config": {"map_by": ["instance", "class"], SEG_KEYS}},
        {"module": "writer.CocoAnnotationsWriter", "config": {}},
        {"module": "writer.BopWriter", "config": {}},
        {"module": "writer.Hdf5Writer", "config": {}}
      ]
    }
"""


def test_output_keys_rename_the_stored_datasets(tmp_path, notices):
    from hybridgen.data import KeypointDataset

    obj = write_scene(tmp_path)
    runs = {}
    for name, rgb_keys, seg_keys in (
            ("default", '"output_key": "colors"', '"segcolormap_output_key": "instance_attribute_maps"'),
            ("renamed", '"output_key": "rgb", "depth_output_key": "depth_m", "normals_output_key": "nrm", '
                        '"distance_output_key": "never_rendered"', '"segcolormap_output_key": "segcolormap"')):
        text = RENAMED_KEYS_V3.replace("RGB_KEYS", rgb_keys).replace("SEG_KEYS", seg_keys)
        out = tmp_path / name
        run_config(write(tmp_path, f"{name}.yaml", text), [str(obj), str(out)])
        runs[name] = read_numbered(out)  # BlenderProc's 0.hdf5, 1.hdf5
        runs[name + "_coco"] = json.loads((out / "coco_data" / "coco_annotations.json").read_text())
    default, renamed = runs["default"], runs["renamed"]
    pairs = {"colors": "rgb", "depth": "depth_m", "normals": "nrm", "instance_attribute_maps": "segcolormap"}
    pairs.update({f"{own}_version": f"{stored}_version" for own, stored in pairs.items()})
    for own, stored in pairs.items():
        assert own in default and own not in renamed and stored in renamed and stored not in default
    assert "never_rendered" not in renamed  # a name for a pass not rendered is no error, as in BlenderProc
    np.testing.assert_array_equal(renamed["rgb"], default["colors"])  # same seed: the same image
    np.testing.assert_array_equal(renamed["depth_m"], default["depth"])
    # renamed or not, normals are BlenderProc's: float32, Blender camera axes, 0.5 n + 0.5
    np.testing.assert_array_equal(renamed["nrm"], default["normals"])
    assert renamed["nrm"][0].dtype == np.float32 and 0.0 <= np.min(renamed["nrm"]) <= np.max(renamed["nrm"]) <= 1.0
    assert [json.loads(v) for v in renamed["segcolormap"]] == [json.loads(v) for v in default["instance_attribute_maps"]]
    for key in set(default) - set(pairs):
        np.testing.assert_array_equal(renamed[key], default[key], err_msg=key)
    # the COCO writer found the renamed passes (finish() points it at segcolormap): the same annotations
    assert runs["renamed_coco"]["annotations"] == runs["default_coco"]["annotations"]
    assert runs["renamed_coco"]["annotations"]
    # the BOP writer found them too (finish() gives it input_keys): the same files, byte for byte
    bop = {name: sorted(p.relative_to(tmp_path / name / "bop_data") for p in (tmp_path / name / "bop_data").rglob("*")
                        if p.is_file()) for name in ("default", "renamed")}
    assert bop["default"] == bop["renamed"] and any(p.parent.name == "depth" for p in bop["default"])
    for path in bop["default"]:
        if path.suffix == ".png":
            assert (tmp_path / "default/bop_data" / path).read_bytes() == \
                (tmp_path / "renamed/bop_data" / path).read_bytes(), path
    # the reader returns renamed passes under their stored name
    samples = list(KeypointDataset(tmp_path / "renamed", keys=["rgb", "depth_m", "nrm"]))
    assert len(samples) == 2
    np.testing.assert_array_equal(samples[1]["rgb"], default["colors"][1])
    np.testing.assert_array_equal(samples[1]["depth_m"], default["depth"][1])


BOP_REPLICATION_V3 = """\
    # Args: <path_to_bop_data> <bop_datset_name> <bop_toolkit_path> <output_dir>
    {
      "version": 3,
      "setup": {"blender_install_path": "/home_local/<env:HYBRIDGEN_TEST_SURELY_UNSET>/blender/",
                "pip": ["h5py", "scikit-image", "pypng==0.0.20"]},
      "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:3>", "sys_paths": ["<args:2>"]}}},
        {"module": "loader.BopLoader", "config": {"source_frame": ["X", "-Y", "-Z"], "bop_dataset_path":
            "<args:0>/<args:1>", "mm2m": True, "split": "test", "scene_id": 1, "model_type": ""}},
        {"module": "lighting.LightLoader", "config": {"lights": [{"type": "POINT", "location": [0, -1, -1],
                                                                  "energy": 100}]}},
        {"module": "renderer.RgbRenderer", "config": {"samples": 1, "render_distance": True,
                                                      "resolution_x": 80, "resolution_y": 60}},
        {"module": "renderer.SegMapRenderer", "config": {"map_by": "instance"}},
        {"module": "writer.BopWriter", "config": {"dataset": "<args:1>", "save_world2cam": False,
            "postprocessing_modules": {"distance": [{"module": "postprocessing.Dist2Depth"}]}}}
      ]
    }
"""


def _bop_standin(tmp_path: Path) -> Path:
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "check_bp", Path(__file__).resolve().parents[2] / "tools" / "check_blenderproc_configs.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module.make_bop_standin(tmp_path / "bop")


def test_bop_scene_replication_round_trips_through_the_bop_writer(tmp_path, notices, monkeypatch):
    monkeypatch.delenv("HYBRIDGEN_TEST_SURELY_UNSET", raising=False)
    dataset = _bop_standin(tmp_path)
    gt_in = json.loads((dataset / "test" / "000001" / "scene_gt.json").read_text())
    config = write(tmp_path, "bop.yaml", BOP_REPLICATION_V3)
    out = tmp_path / "out"
    args = [str(tmp_path / "bop"), "lm", str(tmp_path / "toolkit"), str(out)]
    loaded = load_config(config, args)
    scene = execute(loaded, build_modules(loaded)[:2]).scene
    assert [o.name for o in scene.objects] == ["obj_000001", "obj_000002", "obj_000003"]
    assert [o.category_id for o in scene.objects] == [1, 2, 3]
    assert all(o.attributes["bop_dataset_name"] == "lm" for o in scene.objects)
    for image, instances in gt_in.items():  # every camera sees every object where BOP says it is
        world2cam = np.linalg.inv(scene.camera.keypoints[int(image)])
        for obj, inst in zip(scene.objects, instances):
            m2c = world2cam @ obj.local2world @ np.diag([1000.0, 1000.0, 1000.0, 1.0])  # model in mm
            np.testing.assert_allclose(m2c[:3, :3].ravel(), inst["cam_R_m2c"], atol=1e-9)
            np.testing.assert_allclose(m2c[:3, 3] * 1000, inst["cam_t_m2c"], atol=1e-6)
    run_config(config, args)
    written = out / "bop_data" / "lm" / "train_pbr" / "000000"
    gt_out = json.loads((written / "scene_gt.json").read_text())
    for image, instances in gt_in.items():
        for inst_in, inst_out in zip(instances, gt_out[image]):
            assert inst_out["obj_id"] == inst_in["obj_id"]
            np.testing.assert_allclose(inst_out["cam_R_m2c"], inst_in["cam_R_m2c"], atol=1e-6)
            np.testing.assert_allclose(inst_out["cam_t_m2c"], inst_in["cam_t_m2c"], atol=1e-3)
    assert (written / "rgb" / "000000.png").is_file() and (written / "depth" / "000001.png").is_file()


def test_source_frame_as_blenderprocs_point_and_matrix_conversion():
    from hybridgen.config.camera_poses import pose_from_entry

    frame = ["X", "-Z", "Y"]  # BlenderProc's own example: (1, 2, 3) -> (1, -3, 2)
    pose = pose_from_entry({"location": [1, 2, 3], "rotation": {"format": "forward_vec", "value": [0, 0, -1]}},
                           source_frame=frame)
    np.testing.assert_allclose(pose[:3, 3], [1, -3, 2])
    # a forward vector (0, 0, -1) in a Y-up tool's frame is Blender's (0, 1, 0): the view axis (OpenCV z)
    np.testing.assert_allclose(pose[:3, 2], [0, 1, 0], atol=1e-12)
    # a cam2world given in that frame: its camera axes are converted (change_source_coordinate_frame)
    given = make_pose(look_at_blender([2, -3, 1], [0, 0, 0]), [2, -3, 1])
    T = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float)
    expected = given.copy()
    expected[:3, :3] = given[:3, :3] @ T.T
    np.testing.assert_allclose(pose_from_entry({"cam2world_matrix": given.tolist()}, source_frame=frame),
                               expected @ np.diag([1.0, -1.0, -1.0, 1.0]), atol=1e-12)


def test_output_keys_that_would_store_two_passes_under_one_name_are_refused():
    from hybridgen.io.frame_sink import PassLayout
    from hybridgen.io.renamed_sink import check_output_keys, renamed_layouts

    layouts = [PassLayout("depth", "float32", (2, 2)), PassLayout("normals", "float32", (2, 2, 3))]
    assert [layout.key for layout in renamed_layouts(layouts, {"depth": "d", "albedo": "a"})] == ["d", "normals"]
    with pytest.raises(ConfigError, match="two passes"):
        renamed_layouts(layouts, {"depth": "normals"})
    assert check_output_keys({"depth": "x", "normals": "x"}) is not None
    assert check_output_keys({"depth": "a/b"}) is not None
    assert check_output_keys({"depth": "d"}) is None and check_output_keys(None) is None
