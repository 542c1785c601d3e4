"""Dataset loaders on tiny stand-ins written in each dataset's published layout: object counts, names,
ids/categories as BlenderProc assigns them, transforms and units, and one-line errors for wrong folders."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation

from hybridgen.config.notices import set_sink
from hybridgen.errors import ConfigError
from tests.config.test_blenderproc_modules import run_config_text


def _box_obj(path: Path, low, high, mtl: str | None = None) -> Path:
    """An OBJ box (file axes) spanning ``low``..``high``, with UVs."""
    path.parent.mkdir(parents=True, exist_ok=True)
    (x0, y0, z0), (x1, y1, z1) = low, high
    corners = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = [f"mtllib {mtl}", "usemtl body"] if mtl else []
    lines += [f"v {x} {y} {z}" for x, y, z in corners] + ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1"]
    lines += [f"f {a}/1 {b}/2 {c}/3 {d}/4" for a, b, c, d in quads]
    path.write_text("\n".join(lines) + "\n")
    return path


def _run(tmp_path: Path, module: str, config: dict, seed: int = 1):
    return run_config_text(tmp_path, json.dumps({"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}, "seed": seed}},
        {"module": module, "config": config}]}))


# ---------------------------------------------------------------------------------------------- ShapeNet
@pytest.fixture
def shapenet(tmp_path: Path) -> Path:
    root = tmp_path / "ShapeNetCore.v2"
    root.mkdir()
    (root / "taxonomy.json").write_text(json.dumps([
        {"synsetId": "02691156", "name": "airplane,aeroplane,plane", "children": ["02690373"], "numInstances": 2},
        {"synsetId": "02690373", "name": "airliner", "children": [], "numInstances": 1}]))
    _box_obj(root / "02691156" / "1a04e3eab45ca15dd86060f189eb133" / "models" / "model_normalized.obj",
             (0.0, 2.0, -1.0), (1.0, 3.0, 0.0))
    _box_obj(root / "02691156" / "2b1a867569f9f61a54eefcdc602d4520" / "models" / "model_normalized.obj",
             (-0.2, -0.1, -0.3), (0.2, 0.1, 0.3))
    return root


def test_shapenet_model_with_blenderproc_axes_origin_and_ids(tmp_path, shapenet):
    context = _run(tmp_path, "loader.ShapeNetLoader", {
        "data_path": str(shapenet), "used_synset_id": "02690373",  # a child synset: its parent's folder is used
        "used_source_id": "1a04e3eab45ca15dd86060f189eb133"})
    [obj] = context.scene.objects
    assert obj.attributes["used_synset_id"] == "02690373"
    assert obj.attributes["used_source_id"] == "1a04e3eab45ca15dd86060f189eb133"
    assert obj.category_id is None  # BlenderProc assigns none
    np.testing.assert_array_equal(obj.local2world, np.eye(4))  # the import turn is in the vertices
    # file (x, y, z) -> Blender (x, -z, y): the box spans x 0..1, y 0..1, z 2..3, then its bottom centre
    # (0.5, 0.5, 2) moves to the origin
    np.testing.assert_allclose(obj.world_vertices().min(axis=0), [-0.5, -0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(obj.world_vertices().max(axis=0), [0.5, 0.5, 1.0], atol=1e-12)
    kept = _run(tmp_path, "loader.ShapeNetLoader", {
        "data_path": str(shapenet), "used_synset_id": "02691156", "move_object_origin": False,
        "used_source_id": "1a04e3eab45ca15dd86060f189eb133", "add_properties": {"cp_category_id": 7}})
    [obj] = kept.scene.objects
    np.testing.assert_allclose(obj.world_vertices().min(axis=0), [0.0, 0.0, 2.0], atol=1e-12)
    assert obj.category_id == 7


def test_shapenet_draws_a_model_of_the_synset(tmp_path, shapenet):
    drawn = {_run(tmp_path, "loader.ShapeNetLoader", {"data_path": str(shapenet), "used_synset_id": "02691156"},
                  seed=seed).scene.objects[0].attributes["used_source_id"] for seed in range(8)}
    assert drawn == {"1a04e3eab45ca15dd86060f189eb133", "2b1a867569f9f61a54eefcdc602d4520"}


@pytest.mark.parametrize("change, key, words", [
    ({"data_path": "nowhere"}, "data_path", "ShapeNet folder not found"),
    ({"used_synset_id": "09999999"}, "used_synset_id", "no folder"),
    ({"used_source_id": "nope"}, "used_source_id", "no model 'nope'"),
])
def test_shapenet_errors_name_the_key(tmp_path, shapenet, change, key, words):
    config = {"data_path": str(shapenet), "used_synset_id": "02691156", **change}
    with pytest.raises(ConfigError) as info:
        _run(tmp_path, "loader.ShapeNetLoader", config)
    assert info.value.key == key and words in str(info.value) and "\n" not in str(info.value)
    (shapenet / "taxonomy.json").write_text("{broken")
    with pytest.raises(ConfigError, match="not valid JSON") as info:
        _run(tmp_path, "loader.ShapeNetLoader", {"data_path": str(shapenet), "used_synset_id": "02691156"})
    assert info.value.key == "data_path"


# ---------------------------------------------------------------------------------------------- 3D-FRONT
MAPPING = "id,name\n0,void\n1,floor\n2,wallinner\n3,ceiling\n4,bed\n5,lamp\n6,sofa\n"


@pytest.fixture
def front(tmp_path: Path) -> dict[str, Path]:
    models, textures = tmp_path / "3D-FUTURE-model", tmp_path / "3D-FRONT-texture"
    _box_obj(models / "jid-bed" / "raw_model.obj", (-1.0, 0.0, -0.5), (1.0, 0.6, 0.5))
    Image.new("RGB", (2, 2), (128, 128, 128)).save(models / "jid-bed" / "texture.png")
    _box_obj(models / "jid-lamp" / "raw_model.obj", (-0.1, 0.0, -0.1), (0.1, 0.5, 0.1))
    Image.new("RGB", (2, 2), (255, 188, 0)).save(models / "jid-lamp" / "texture.png")
    (textures / "0a1b2c").mkdir(parents=True)
    Image.new("RGB", (2, 2), (10, 200, 30)).save(textures / "0a1b2c" / "texture.png")
    quad = {"uv": [0, 0, 1, 0, 1, 1, 0, 1], "faces": [0, 1, 2, 0, 2, 3]}
    house = {
        "uid": "house-1",
        "material": [{"uid": "m-floor", "texture": "https://cdn.example/0a1b2c/texture.png", "normaltexture": "",
                      "color": [255, 255, 255, 255]},
                     {"uid": "m-wall", "texture": "", "normaltexture": "", "color": [204, 51, 0, 255]},
                     {"uid": "m-ceiling", "texture": "", "normaltexture": "", "color": [250, 250, 250, 255]}],
        "mesh": [  # 3D-FRONT is y up: floor in y = 0, ceiling at y = 2.8, a wall in z = 0
            {"uid": "mesh-floor", "type": "Floor", "material": "m-floor", **quad,
             "xyz": [0, 0, 0, 4, 0, 0, 4, 0, 3, 0, 0, 3], "normal": [0, 1, 0] * 4},
            {"uid": "mesh-wall", "type": "WallInner ", "material": "m-wall", **quad,
             "xyz": [0, 0, 0, 4, 0, 0, 4, 2.8, 0, 0, 2.8, 0], "normal": [0, 0, 1] * 4},
            {"uid": "mesh-ceiling", "type": "Ceiling", "material": "m-ceiling", **quad,
             "xyz": [0, 2.8, 0, 0, 2.8, 3, 4, 2.8, 3, 4, 2.8, 0], "normal": [0, -1, 0] * 4},
            {"uid": "mesh-nomat", "type": "Floor", **quad, "xyz": [0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1],
             "normal": [0, 1, 0] * 4}],
        "furniture": [{"uid": "f-bed", "jid": "jid-bed", "category": "Bed", "title": "bed/double"},
                      {"uid": "f-lamp", "jid": "jid-lamp", "title": "lamp/floor lamp"},
                      {"uid": "f-sofa", "jid": "jid-missing", "category": "sofa"}],
        "scene": {"room": [
            {"instanceid": "Bedroom-1", "children": [
                {"ref": "f-bed", "instanceid": "furniture/1", "pos": [1.0, 0.0, 1.5], "rot": [0, 0.70711, 0, 0.70711],
                 "scale": [1, 1, 1]},
                {"ref": "f-bed", "instanceid": "furniture/2", "pos": [3.0, 0.0, 2.0], "rot": [0, 0, 0, 1],
                 "scale": [1.2, 1, 0.8]},
                {"ref": "mesh-floor", "instanceid": "mesh/3", "pos": [0, 0, 0], "rot": [0, 0, 0, 1], "scale": [1, 1, 1]}]},
            {"instanceid": "LivingRoom-2", "children": [
                {"ref": "f-lamp", "instanceid": "furniture/4", "pos": [0.5, 0.0, 0.5], "rot": [0, 0, 0, 1],
                 "scale": [1, 1, 1]},
                {"ref": "f-sofa", "instanceid": "furniture/5", "pos": [2, 0, 2], "rot": [0, 0, 0, 1], "scale": [1, 1, 1]}]}]},
    }
    json_path = tmp_path / "house.json"
    json_path.write_text(json.dumps(house))
    mapping = tmp_path / "3D_front_mapping.csv"
    mapping.write_text(MAPPING)
    return {"json_path": json_path, "3D_future_model_path": models, "3D_front_texture_path": textures,
            "mapping_file": mapping}


def _front_config(front: dict[str, Path], **change) -> dict:
    return {**{k: str(v) for k, v in front.items()}, **change}


def _blenderproc_pose(child: dict) -> np.ndarray:
    """Blender's matrix_world T . R . S of a room child, with BlenderProc's Quaternion(rot) (w first) and its
    extra -90 deg turn about x (scipy's rotations, written independently of the loader)."""
    w, x, y, z = child["rot"]
    rotation = Rotation.from_euler("x", -90, degrees=True) * Rotation.from_quat([x, y, z, w])
    pose = np.eye(4)
    pose[:3, :3] = rotation.as_matrix() @ np.diag(child["scale"])
    pose[:3, 3] = np.array(child["pos"])[[0, 2, 1]]
    return pose


def test_front3d_house_meshes_of_one_type_get_blenders_names(tmp_path, front):
    """BlenderProc makes one Blender object per mesh entry, named by its type: a second Floor is Floor.001."""
    house = json.loads(front["json_path"].read_text())
    second = dict(house["mesh"][0], uid="mesh-floor-2", xyz=[4, 0, 0, 6, 0, 0, 6, 0, 3, 4, 0, 3])
    house["mesh"].insert(1, second)
    front["json_path"].write_text(json.dumps(house))
    objects = _run(tmp_path, "loader.Front3DLoader", _front_config(front)).scene.objects
    assert [o.name for o in objects][:4] == ["Floor", "Floor.001", "WallInner", "Ceiling"]
    np.testing.assert_allclose(objects[1].world_vertices()[:, 0], [4, 6, 6, 4])
    assert objects[0].category_id == objects[1].category_id == 1


def test_front3d_house_rooms_furniture_categories_and_poses(tmp_path, front):
    lines: list[str] = []
    set_sink(lines.append)
    try:
        context = _run(tmp_path, "loader.Front3DLoader", _front_config(front))
    finally:
        set_sink(None)
    objects = context.scene.objects
    assert [o.name for o in objects] == ["Floor", "WallInner", "Ceiling", "Bed", "Bed.001", "lamp"]
    assert [o.category_id for o in objects] == [1, 2, 3, 4, 4, 5]
    assert all(o.attributes["is_3d_front"] for o in objects)
    assert any("1 mesh entry without a material" in line for line in lines)
    assert any("1 furniture model(s) without raw_model.obj" in line and "jid-missing" in line for line in lines)
    floor, wall, ceiling, bed, bed2, lamp = objects
    # y and z exchanged: the floor lies in z = 0 with normal +z, the ceiling at z = 2.8
    np.testing.assert_allclose(floor.world_vertices(), [[0, 0, 0], [4, 0, 0], [4, 3, 0], [0, 3, 0]])
    np.testing.assert_allclose(floor.vertex_normals, [[0, 0, 1]] * 4)
    assert np.allclose(ceiling.world_vertices()[:, 2], 2.8) and np.allclose(wall.world_vertices()[:, 1], 0)
    assert floor.material.base_color_texture == str(front["3D_front_texture_path"] / "0a1b2c" / "texture.png")
    np.testing.assert_allclose(wall.material.base_color, (0.8, 0.2, 0.0, 1.0))
    assert wall.material.emission_strength == 0 and ceiling.material.emission_strength == 0.8
    np.testing.assert_allclose(ceiling.material.emission, [250 / 255] * 3)
    # furniture: the room child's pose on the OBJ as stored; one parse shared by both beds
    house = json.loads(front["json_path"].read_text())
    children = house["scene"]["room"][0]["children"]
    file_vertices = bed.vertices  # the OBJ's own coordinates
    assert file_vertices.min(axis=0) == pytest.approx([-1.0, 0.0, -0.5])
    for obj, child in ((bed, children[0]), (bed2, children[1])):
        np.testing.assert_allclose(obj.local2world, _blenderproc_pose(child), atol=1e-5)
        assert obj.attributes["room_id"] == 0 and obj.attributes["uid"] == "f-bed"
        assert obj.attributes["coarse_grained_class"] == 4 and obj.material.roughness == 0.5
        # the file's up (+y) ends up along world +z: the bed stands on the floor
        up = obj.local2world[:3, :3] @ [0, 1, 0]
        assert up[2] > 0.99 and abs(obj.world_vertices()[:, 2].min()) < 1e-6
    assert bed2.vertices is bed.vertices and bed2.faces is bed.faces  # instanced: the arrays are shared
    np.testing.assert_allclose(bed2.world_vertices()[:, [0, 1]].max(axis=0), [3 + 1.2 * 1.0, 2 + 0.8 * 0.5], atol=1e-5)
    assert lamp.attributes["room_id"] == 1 and lamp.material.emission_strength == 7.0
    srgb = np.array([255, 188, 0]) / 255
    np.testing.assert_allclose(lamp.material.emission, np.where(srgb <= 0.04045, srgb / 12.92,
                                                                ((srgb + 0.055) / 1.055) ** 2.4), atol=1e-6)
    assert lamp.material.base_color_texture.endswith("jid-lamp/texture.png")
    # BlenderProc's make_emissive: the lamp's base color (its texture) emits; ceiling and lamp light the room
    # but show the camera their surface (render/pathtrace/camera_hidden_emission.py)
    assert lamp.material.emission_texture == lamp.material.base_color_texture
    assert ceiling.material.emission_hidden_from_camera and lamp.material.emission_hidden_from_camera
    assert not wall.material.emission_hidden_from_camera


@pytest.mark.parametrize("change, key, words", [
    ({"mapping_file": "missing.csv"}, "mapping_file", "label mapping CSV not found"),
    ({"3D_future_model_path": "nowhere"}, "3D_future_model_path", "3D-FUTURE model folder not found"),
    ({"3D_front_texture_path": "nowhere"}, "3D_front_texture_path", "3D-FRONT texture not found"),
    ({"json_path": "house.txt"}, "json_path", "not a .json file"),
])
def test_front3d_errors_name_the_key(tmp_path, front, change, key, words):
    with pytest.raises(ConfigError) as info:
        _run(tmp_path, "loader.Front3DLoader", _front_config(front, **change))
    assert info.value.key == key and words in str(info.value) and "\n" not in str(info.value)


def test_front3d_unknown_label_and_broken_json(tmp_path, front):
    front["mapping_file"].write_text("id,name\n0,void\n1,floor\n")
    with pytest.raises(ConfigError, match="label 'wallinner' is not in the label mapping") as info:
        _run(tmp_path, "loader.Front3DLoader", _front_config(front))
    assert info.value.key == "mapping_file"
    front["json_path"].write_text('{"scene": ')
    with pytest.raises(ConfigError, match="not valid JSON") as info:
        _run(tmp_path, "loader.Front3DLoader", _front_config(front))
    assert info.value.key == "json_path"
    front["json_path"].write_text('{"mesh": []}')
    with pytest.raises(ConfigError, match="has no 'scene'"):
        _run(tmp_path, "loader.Front3DLoader", _front_config(front))


# ---------------------------------------------------------------------------------------------- Replica
def test_replica_mesh_with_vertex_colors_as_stored(tmp_path):
    import trimesh

    mesh = trimesh.Trimesh([[0, 0, 0], [2, 0, 0], [0, 3, 0], [0, 0, 1.5]], [[0, 1, 2], [0, 1, 3]], process=False)
    mesh.visual.vertex_colors = [[255, 0, 0, 255]] * 2 + [[0, 0, 255, 255]] * 2
    (tmp_path / "replica" / "office_1").mkdir(parents=True)
    mesh.export(tmp_path / "replica" / "office_1" / "mesh.ply")
    context = _run(tmp_path, "loader.ReplicaLoader", {"data_path": str(tmp_path / "replica"),
                                                      "data_set_name": "office_1",
                                                      "add_properties": {"cp_category_id": 3}})
    [obj] = context.scene.objects
    np.testing.assert_allclose(obj.world_vertices(), mesh.vertices)  # z up as stored, metres
    assert obj.category_id == 3 and obj.material.base_color_from_vertices
    np.testing.assert_allclose(obj.vertex_colors, [[1, 0, 0]] * 2 + [[0, 0, 1]] * 2)
    with pytest.raises(ConfigError, match="Replica mesh not found") as info:
        _run(tmp_path, "loader.ReplicaLoader", {"data_path": str(tmp_path / "replica"), "data_set_name": "room_0"})
    assert info.value.key == "data_set_name"


# ---------------------------------------------------------------------------------------------- Pix3D
def test_pix3d_model_of_a_category(tmp_path):
    root = tmp_path / "pix3d"
    _box_obj(root / "model" / "chair" / "IKEA_A" / "model.obj", (-0.3, 0.0, -0.2), (0.3, 0.9, 0.2))
    _box_obj(root / "model" / "chair" / "IKEA_B" / "model.obj", (0.0, 1.0, 0.0), (0.4, 1.5, 0.4))
    _box_obj(root / "model" / "bed" / "X" / "model.obj", (0, 0, 0), (2, 1, 1))
    annotations = [{"img": f"img/chair/{i}.jpg", "category": "chair", "model": f"model/chair/IKEA_{m}/model.obj"}
                   for i, m in enumerate("AAB")] + [{"category": "bed", "model": "model/bed/X/model.obj"}]
    (root / "pix3d.json").write_text(json.dumps(annotations))
    drawn = set()
    for seed in range(8):
        [obj] = _run(tmp_path, "loader.Pix3DLoader", {"data_path": str(root), "used_category": "chair"},
                     seed=seed).scene.objects
        drawn.add(obj.attributes["source_path"])
        size = obj.world_vertices().max(axis=0) - obj.world_vertices().min(axis=0)
        # Blender's OBJ axes (file y up -> z), origin at the bottom centre
        np.testing.assert_allclose(obj.world_vertices().min(axis=0), -size * [0.5, 0.5, 0])
    assert {Path(p).parent.name for p in drawn} == {"IKEA_A", "IKEA_B"}
    assert not list(root.glob("category_*"))  # nothing written into the dataset
    with pytest.raises(ConfigError, match="no model of category 'lamp'.*bed, chair") as info:
        _run(tmp_path, "loader.Pix3DLoader", {"data_path": str(root), "used_category": "lamp"})
    assert info.value.key == "used_category"


# ---------------------------------------------------------------------------------------------- IKEA
def test_ikea_units_names_and_selection(tmp_path):
    root = tmp_path / "ikea"
    chair = _box_obj(root / "IKEA" / "IKEA_chair_POANG" / "poang.obj", (0, 0, 0), (20, 30, 10), mtl="poang.mtl")
    chair.write_text("# File units = inches\n" + chair.read_text())
    (chair.parent / "poang.mtl").write_text("newmtl body\nKd 0.5 0.4 0.3\n")
    bed = _box_obj(root / "IKEA" / "IKEA_bed_MALM" / "malm.obj", (0, 0, 0), (200, 50, 100), mtl="malm.mtl")
    bed.write_text("# File units: centimeters\n" + bed.read_text())
    (bed.parent / "malm.mtl").write_text("newmtl body\nKd 0.5 0.4 0.3\n")
    _box_obj(root / "IKEA" / "IKEA_bed_HEMNES" / "no_mtl.obj", (0, 0, 0), (1, 1, 1))  # no .mtl: not a candidate
    [obj] = _run(tmp_path, "loader.IKEALoader", {"data_dir": str(root), "category": "chair"}).scene.objects
    assert obj.name == "IKEA_chair_POANG"
    size = obj.world_vertices().max(axis=0) - obj.world_vertices().min(axis=0)
    np.testing.assert_allclose(size, np.array([20, 10, 30]) * 0.0254)  # inches -> m, y up -> z
    np.testing.assert_allclose(obj.world_vertices().min(axis=0), -size * [0.5, 0.5, 0], atol=1e-12)
    [obj] = _run(tmp_path, "loader.IKEALoader", {"data_dir": str(root), "style": "malm"}).scene.objects
    assert obj.name == "IKEA_bed_MALM"
    np.testing.assert_allclose(obj.world_vertices().max(axis=0) - obj.world_vertices().min(axis=0), [2, 1, 0.5])
    lines: list[str] = []
    set_sink(lines.append)
    try:
        [obj] = _run(tmp_path, "loader.IKEALoader", {"data_dir": str(root), "category": "sofa",
                                                     "style": "poang"}).scene.objects
    finally:
        set_sink(None)
    assert obj.name in ("IKEA_chair_POANG", "IKEA_bed_MALM") and any("a random model" in line for line in lines)
    with pytest.raises(ConfigError, match="no IKEA/IKEA_") as info:
        _run(tmp_path, "loader.IKEALoader", {"data_dir": str(tmp_path)})
    assert info.value.key == "data_dir"


# ---------------------------------------------------------------------------------------------- SceneNet
def test_scenenet_room_textures_and_nyu_categories(tmp_path):
    room = tmp_path / "scenenet" / "1Bedroom" / "bedroom1.obj"
    room.parent.mkdir(parents=True)
    (room.parent / "bedroom1.mtl").write_text("".join(f"newmtl {m}\nKd 0.5 0.5 0.5\n"
                                                      for m in ("bed_01", "Wood_2.001", "ground_mat", "misc")))
    parts = [("Bed.003", "bed_01", 0), ("Nightstand", "Wood_2.001", 2), ("ground", "ground_mat", 4),
             ("Paintings_1", "misc", 6), ("Chairs", "misc", 8), ("Thing", "misc", 10), ("Wall.002", "misc", 12)]
    lines = ["mtllib bedroom1.mtl", "vt 0 0", "vt 1 0", "vt 1 1"]
    for index, (name, material, x) in enumerate(parts):
        lines += [f"o {name}", f"usemtl {material}", f"v {x} 0 0", f"v {x + 1} 0 0", f"v {x} 1 0", "vn 0 0 1",
                  f"f {3 * index + 1}/1/1 {3 * index + 2}/2/1 {3 * index + 3}/3/1"]
    room.write_text("\n".join(lines) + "\n")
    textures = tmp_path / "textures"
    for folder, count in (("bed", 2), ("Wood", 1), ("unknown", 1)):
        for i in range(count):
            _image_file(textures / folder / f"{folder}_{i}.jpg")
    (tmp_path / "nyu.csv").write_text("id,name\n0,void\n1,wall\n2,floor\n3,bed\n4,night_stand\n5,picture\n"
                                      "6,chair\n7,ceiling\n8,otherstructure\n")
    context = _run(tmp_path, "loader.SceneNetLoader", {"file_path": str(room), "texture_folder": str(textures),
                                                       "mapping_file": str(tmp_path / "nyu.csv")})
    by_name = {o.name: o for o in context.scene.objects}
    assert sorted(by_name) == ["Bed.003", "Chairs", "Nightstand", "Paintings_1", "Thing", "Wall.002", "floor"]
    expected = {"Bed.003": 3, "Chairs": 6, "Nightstand": 4, "Paintings_1": 5, "Thing": 8, "Wall.002": 1, "floor": 2}
    assert {n: o.category_id for n, o in by_name.items()} == expected  # plural 'chairs' -> chair
    assert Path(by_name["Bed.003"].material.base_color_texture).parent.name == "bed"
    assert Path(by_name["Nightstand"].material.base_color_texture).name == "Wood_0.jpg"  # 'Wood_2.001' -> Wood
    assert Path(by_name["Thing"].material.base_color_texture).parent.name == "unknown"
    # flat shading by the file's name (as BlenderProc, before 'ground' is renamed floor)
    assert by_name["Wall.002"].vertex_normals is None and by_name["floor"].vertex_normals is not None
    assert all(o.attributes["is_scene_net_obj"] for o in by_name.values())
    with pytest.raises(ConfigError, match="unknown texture folder") as info:
        _run(tmp_path, "loader.SceneNetLoader", {"file_path": str(room), "texture_folder": str(textures),
                                                 "unknown_texture_folder": str(tmp_path / "none"),
                                                 "mapping_file": str(tmp_path / "nyu.csv")})
    assert info.value.key == "unknown_texture_folder"


def _image_file(path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (2, 2), (90, 90, 90)).save(path)
