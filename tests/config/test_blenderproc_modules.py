"""Modules that exist for BlenderProc configs: constructor.BasicMeshInitializer, object.FloorExtractor,
loader.CCMaterialLoader + cf_randomize_materials, manipulators.WorldManipulator, the state writers,
object.ObjectReplacer and every module name of BlenderProc 1.0 / 1.12 resolving (or saying why not)."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hybridgen.config.blenderproc import ALIASES, UNAVAILABLE, unavailable_reason
from hybridgen.config.config_file import load_config
from hybridgen.config.notices import set_sink
from hybridgen.config.registry import all_modules, get_module
from hybridgen.errors import ConfigError
from hybridgen.run.pipeline import build_modules, execute

# Every module name BlenderProc 1.0 and 1.12's examples use (the names only, listed here by hand).
BLENDERPROC_MODULES = """
main.Initializer renderer.RgbRenderer writer.Hdf5Writer manipulators.MaterialManipulator
manipulators.EntityManipulator loader.BopLoader lighting.LightLoader camera.CameraLoader camera.CameraSampler
loader.ObjectLoader renderer.SegMapRenderer object.PhysicsPositioning lighting.LightSampler loader.CCMaterialLoader
writer.BopWriter object.ObjectPoseSampler constructor.BasicMeshInitializer loader.ShapeNetLoader loader.SuncgLoader
lighting.SuncgLighting loader.BlendLoader lighting.SurfaceLighting writer.CameraStateWriter object.FloorExtractor
loader.ObjLoader renderer.NormalRenderer manipulators.WorldManipulator writer.CocoAnnotationsWriter
camera.SuncgCameraSampler object.OnSurfaceSampler loader.SceneNetLoader loader.HavenEnvironmentLoader
writer.ObjectStateWriter writer.LightStateWriter loader.Front3DLoader camera.Front3DCameraSampler
camera.ReplicaCameraSampler object.PositionSampler object.CalibrationboardSampler constructor.BasicEmptyInitializer
renderer.FlowRenderer constructor.RandomRoomConstructor writer.StereoGlobalMatchingWriter loader.AMASSLoader
composite.CameraObjectSampler loader.IKEALoader loader.Pix3DLoader loader.ReplicaLoader
loader.RockEssentialsRockLoader constructor.RockEssentialsGroundConstructor materials.RockEssentialsTextureSampler
writer.ShapeNetWriter object.ObjectReplacer loader.PlyLoader manipulators.FloorExtractor
loader.TextureLoader loader.VisNormalImage
""".split()


def test_every_blenderproc_module_name_resolves_or_says_why():
    known = all_modules()
    for name in BLENDERPROC_MODULES:
        if unavailable_reason(name) is not None:
            with pytest.raises(ConfigError) as info:
                get_module(name)
            assert "not available in hybridgen" in str(info.value) and "unknown module" not in str(info.value)
        else:
            cls = get_module(name)
            assert cls is known[ALIASES.get(name, name)]


def test_a_registered_module_wins_over_its_unavailable_entry(monkeypatch):
    """A loader added since (or a plugin) under a name listed as unavailable is the module that runs."""
    from hybridgen.config import registry

    name = "writer.StereoGlobalMatchingWriter"  # (loader.Pix3DLoader, then loader.AMASSLoader were the example)
    assert name in UNAVAILABLE
    all_modules()
    if name not in registry.MODULES:
        with pytest.raises(ConfigError, match="not available in hybridgen"):
            get_module(name)
    stand_in = type("SgmStandIn", (), {})
    monkeypatch.setitem(registry.MODULES, name, stand_in)
    assert unavailable_reason(name) is None and get_module(name) is stand_in


def run_config_text(tmp_path: Path, text: str, args: list[str] | None = None):
    path = tmp_path / "config.yaml"
    path.write_text(textwrap.dedent(text))
    loaded = load_config(path, args or [])
    return execute(loaded, build_modules(loaded))


HEADER = """\
    {"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
      {"module": "main.Initializer", "config": {"global": {"output_dir": "%s"}}},
"""


def test_basic_mesh_initializer_builds_blenders_primitives(tmp_path):
    context = run_config_text(tmp_path, HEADER % tmp_path + """\
      {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
        {"type": "plane", "name": "ground_plane0", "scale": [2, 2, 1], "location": [0, 0, -1],
         "add_properties": {"cp_category_id": 4, "cp_physics": false}},
        {"type": "cube"}]}}
    ]}
    """)
    plane, cube = context.scene.objects
    assert plane.name == "ground_plane0" and cube.name == "Cube"  # Blender's default name
    world = plane.world_vertices()
    np.testing.assert_allclose(np.ptp(world, axis=0), [4, 4, 0], atol=1e-12)  # Blender's plane is 2 x 2
    np.testing.assert_allclose(world[:, 2], -1.0)
    assert plane.category_id == 4 and plane.attributes["physics"] is False
    np.testing.assert_allclose(np.ptp(cube.world_vertices(), axis=0), [2, 2, 2])


def test_floor_extractor_splits_the_floor_faces(tmp_path):
    # one Y-up object holding a floor (y = 0, normal +Y) and a box standing on it
    room = ["o Room", "v -3 0 3", "v 3 0 3", "v 3 0 -3", "v -3 0 -3", "f 1 2 3", "f 1 3 4"]
    room += ["v -0.5 1 0.5", "v 0.5 1 0.5", "v 0.5 1 -0.5", "v -0.5 1 -0.5", "f 5 6 7", "f 5 7 8",
             "v -0.5 0.02 0.5", "v 0.5 0.02 0.5", "f 9 10 6", "f 9 6 5"]
    (tmp_path / "room.obj").write_text("\n".join(room) + "\n")
    context = run_config_text(tmp_path, HEADER % tmp_path + f"""\
      {{"module": "loader.ObjectLoader", "config": {{"path": "{tmp_path / 'room.obj'}"}}}},
      {{"module": "object.FloorExtractor", "config": {{
          "selector": {{"provider": "getter.Entity", "conditions": {{"name": "Room"}}}},
          "compare_angle_degrees": 7.5, "compare_height": 0.05, "name_for_split_obj": "floor",
          "add_properties": {{"cp_category_id": 9}}}}}}
    ]}}
    """)
    names = [o.name for o in context.scene.objects]
    assert names == ["Room", "floor"]
    room_obj, floor = context.scene.objects
    assert len(floor.faces) == 2 and len(room_obj.faces) == 4 and floor.category_id == 9
    np.testing.assert_allclose(floor.world_vertices()[:, 2], 0.0, atol=1e-12)  # Y-up floor -> z = 0
    np.testing.assert_allclose(floor.face_normals @ floor.local2world[:3, :3].T, [[0, 0, 1]] * 2, atol=1e-12)
    assert room_obj.instance_id == 1 and floor.instance_id == 2


def test_cc_materials_and_randomize_materials_once_for_all(tmp_path):
    for asset, color in (("Bricks001", (200, 0, 0)), ("Wood002", (0, 200, 0)), ("Other003", (0, 0, 200))):
        (tmp_path / "cc" / asset).mkdir(parents=True)
        Image.new("RGB", (4, 4), color).save(tmp_path / "cc" / asset / f"{asset}_2K_Color.jpg")
    lines: list[str] = []
    set_sink(lines.append)
    try:
        context = run_config_text(tmp_path, HEADER % tmp_path + f"""\
          {{"module": "constructor.BasicMeshInitializer", "config": {{"meshes_to_add": [
            {{"type": "plane", "name": "ground_plane0"}}, {{"type": "plane", "name": "ground_plane1"}},
            {{"type": "plane", "name": "other"}}]}}}},
          {{"module": "loader.CCMaterialLoader", "config": {{"folder_path": "{tmp_path / 'cc'}",
                                                           "used_assets": ["Bricks", "Wood"]}}}},
          {{"module": "manipulators.EntityManipulator", "config": {{
              "selector": {{"provider": "getter.Entity", "conditions": {{"name": "ground_plane.*"}}}},
              "mode": "once_for_all",
              "cf_randomize_materials": {{"randomization_level": 1, "materials_to_replace_with": {{
                  "provider": "getter.Material", "random_samples": 1, "conditions": {{"cp_is_cc_texture": True}}}}}}}}}}
        ]}}
        """)
    finally:
        set_sink(None)
    ground = [o for o in context.scene.objects if o.name.startswith("ground_plane")]
    names = {o.material.name for o in ground}
    assert len(names) == 1 and names <= {"Bricks001", "Wood002"}  # one draw for all, only used_assets
    assert context.scene.by_name("other").material.name == "plane_material"
    for obj in ground:  # Blender's plane UVs: [0, 1] over the plane
        assert obj.uvs is not None and obj.uvs.min() == 0 and obj.uvs.max() == 1
    assert not any("only the color image" in line for line in lines)  # every map is read now
    picked = ground[0].material
    assert picked.base_color_texture.endswith(f"{picked.name}_2K_Color.jpg") and picked.specular == 0.333
    assert picked.roughness_texture is None and picked.normal_texture is None  # these assets have no maps


def test_world_manipulator_state_writers_and_replacer(tmp_path):
    lines: list[str] = []
    set_sink(lines.append)
    try:
        context = run_config_text(tmp_path, HEADER % tmp_path + """\
          {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
            {"type": "cube", "name": "box", "add_properties": {"cp_category_id": 1, "cp_replace": true}},
            {"type": "uvsphere", "name": "ball", "location": [30, 0, 0],
             "add_properties": {"cp_category_id": 2, "cp_pool": true}}]}},
          {"module": "object.ObjectReplacer", "config": {
              "objects_to_be_replaced": {"provider": "getter.Entity", "conditions": {"cp_replace": true}},
              "objects_to_replace_with": {"provider": "getter.Entity", "conditions": {"cp_pool": true}},
              "replace_ratio": 1, "copy_properties": true}},
          {"module": "manipulators.WorldManipulator", "config": {"cf_set_world_category_id": 0,
                                                                  "color": [0.2, 0.3, 0.4], "strength": 2}},
          {"module": "writer.ObjectStateWriter"},
          {"module": "writer.CameraStateWriter", "config": {"attributes_to_write": ["location", "cam_K"]}},
          {"module": "writer.LightStateWriter"},
          {"module": "writer.Hdf5Writer"}
        ]}
        """)
    finally:
        set_sink(None)
    world = context.scene.world
    assert tuple(world.color) == (0.2, 0.3, 0.4) and world.strength == 2
    (swapped,) = context.scene.objects  # the ball replaced the box, taking its place and id
    assert swapped.instance_id == 1 and swapped.attributes.get("swapped_from") == "box"
    np.testing.assert_allclose(swapped.local2world[:3, 3], [0, 0, 0], atol=1e-9)
    assert sum("object_states" in line for line in lines) == 1
    with pytest.raises(ConfigError, match="writer.Hdf5Writer"):
        run_config_text(tmp_path, HEADER % tmp_path + '{"module": "writer.ObjectStateWriter"}]}')


def test_attribute_merger_sums_or_averages_drawn_elements():
    from hybridgen.sampling.registry import DrawContext, draw, parse_value

    spec = {"provider": "getter.AttributeMerger", "transform_by": "sum",
            "elements": [[1.0, 2.0, 3.0], {"provider": "sampler.Uniform3d", "min": [0.5, 0.5, 0.5],
                                           "max": [0.5, 0.5, 0.5]}]}
    ctx = DrawContext(np.random.default_rng(0), None)
    np.testing.assert_allclose(draw(parse_value(spec, "value"), ctx), [1.5, 2.5, 3.5])
    spec["transform_by"] = "avg"
    np.testing.assert_allclose(draw(parse_value(spec, "value"), ctx), [0.75, 1.25, 1.75])
    spec["transform_by"] = "max"
    with pytest.raises(ConfigError, match="transform_by"):
        parse_value(spec, "value")


def test_hide_takes_objects_out_of_the_scene_keeping_ids(tmp_path):
    context = run_config_text(tmp_path, HEADER % tmp_path + """\
      {"module": "constructor.BasicMeshInitializer", "config": {"meshes_to_add": [
        {"type": "cube", "name": "a"}, {"type": "cube", "name": "b"}, {"type": "cube", "name": "c"}]}},
      {"module": "object.Hide", "config": {"selector": {"provider": "getter.Entity", "conditions": {"name": "b"}}}}
    ]}
    """)
    assert [(o.name, o.instance_id) for o in context.scene.objects] == [("a", 1), ("c", 3)]


def test_lazy_builtin_table_names_the_file_that_registers_each_module():
    """get_module imports only the file _BUILTIN_NAMES gives for a built-in name: each entry must be where that
    name is registered (names missing from the table still resolve, after every module is loaded)."""
    from hybridgen.config import registry

    modules = registry.all_modules()
    assert registry._BUILTIN_NAMES
    for name, package in registry._BUILTIN_NAMES.items():
        assert name in modules and modules[name].__module__ == package, name
        assert registry.get_module(name) is modules[name]
