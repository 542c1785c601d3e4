"""bproc.loader's dataset loaders on small datasets in the published layouts: BOP objects, scenes and intrinsics
(poses against the BOP files), ShapeNet / Pix3D / IKEA / SceneNet / 3D-FRONT / Replica / Matterport3D, CC and
Poly Haven materials, textures, HDRIs, URDF robots, .blend files (with the bpy venv), and
bproc.utility.LabelIdMapping / resolve_resource. Nothing here renders."""
from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image
from writer_session import bproc  # noqa: F401 - the fixture

from hybridgen.errors import InputError

REPO = Path(__file__).resolve().parents[2]


def _bop(root: Path, name: str = "lm") -> Path:
    """Two box models (mm), camera.json, models_info.json and test scene 1 with two images."""
    dataset = root / name
    (dataset / "models").mkdir(parents=True)
    info = {}
    for obj_id, extents in ((1, (60, 40, 30)), (2, (30, 30, 80))):
        box = trimesh.creation.box(extents=extents)
        box.visual.vertex_colors = np.tile([200, 100, 50, 255], (len(box.vertices), 1))
        box.export(dataset / "models" / f"obj_{obj_id:06d}.ply")
        info[str(obj_id)] = {"diameter": 100.0}
    (dataset / "models" / "models_info.json").write_text(json.dumps(info))
    (dataset / "camera.json").write_text(json.dumps({"fx": 500.0, "fy": 510.0, "cx": 300.0, "cy": 250.0,
                                                     "width": 640, "height": 480}))
    gt, cams = {}, {}
    for image, turn in ((0, 0.0), (1, 0.4)):
        rotation = trimesh.transformations.rotation_matrix(turn, [0, 1, 0])[:3, :3]
        gt[str(image)] = [{"obj_id": obj_id, "cam_R_m2c": rotation.ravel().tolist(),
                           "cam_t_m2c": (rotation @ np.array([x, 10.0, 0.0]) + [0, 0, 500.0]).tolist()}
                          for obj_id, x in ((1, -50.0), (2, 50.0))]
        cams[str(image)] = {"cam_K": [500.0, 0, 300.0, 0, 510.0, 250.0, 0, 0, 1]}
    scene = dataset / "test" / "000001"
    scene.mkdir(parents=True)
    (scene / "scene_gt.json").write_text(json.dumps(gt))
    (scene / "scene_camera.json").write_text(json.dumps(cams))
    return dataset


def _box_obj(path: Path, size: tuple[float, float, float], mtl: bool = False) -> None:
    """A y-up box OBJ standing on y = 0."""
    path.parent.mkdir(parents=True, exist_ok=True)
    x, y, z = (s / 2 for s in size)
    corners = [(a, b, c) for a in (-x, x) for b in (0, 2 * y) for c in (-z, z)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = ([f"mtllib {path.stem}.mtl", "usemtl body"] if mtl else []) + [f"v {a} {b} {c}" for a, b, c in corners]
    lines += [f"f {a} {b} {c} {d}" for a, b, c, d in quads]
    path.write_text("\n".join(lines) + "\n")
    if mtl:
        path.with_suffix(".mtl").write_text("newmtl body\nKd 0.6 0.5 0.4\n")


def test_label_id_mapping_from_csv_and_dict(tmp_path, monkeypatch):
    from hybridgen.bproc.utility import LabelIdMapping, resolve_resource

    csv_file = tmp_path / "labels.csv"
    csv_file.write_text("id,name,other\n0,void,x\n3,chair,y\n7,floor,z\n")
    mapping = LabelIdMapping.from_csv(str(csv_file))
    assert mapping.id_from_label("chair") == 3 and mapping.label_from_id(7) == "floor"
    assert mapping.has_label("void") and not mapping.has_id(4) and mapping.num_ids == 8
    other = LabelIdMapping.from_csv(str(csv_file), label_col_name="other")
    assert other.id_from_label("y") == 3
    with pytest.raises(InputError, match="already exists a label-id mapping for the id 3"):
        mapping.add("table", 3)
    assert LabelIdMapping.from_dict({"a": 1, "b": 2}).label_from_id(2) == "b"
    with pytest.raises(InputError, match="no column 'label'"):
        LabelIdMapping.from_csv(str(csv_file), label_col_name="label")
    (tmp_path / "res" / "id_mappings").mkdir(parents=True)
    (tmp_path / "res" / "id_mappings" / "x.csv").write_text("id,name\n")
    monkeypatch.setenv("HYBRIDGEN_BPROC_RESOURCES", str(tmp_path / "res"))
    assert resolve_resource("id_mappings/x.csv") == str(tmp_path / "res" / "id_mappings" / "x.csv")
    monkeypatch.delenv("HYBRIDGEN_BPROC_RESOURCES")
    monkeypatch.chdir(tmp_path)
    assert resolve_resource("id_mappings/x.csv") == str(tmp_path / "blenderproc" / "resources" / "id_mappings"
                                                        / "x.csv")


def test_bop_objects_are_scaled_named_and_drawn_as_blenderproc(bproc, tmp_path):
    dataset = _bop(tmp_path)
    objects = bproc.loader.load_bop_objs(str(dataset), object_model_unit="mm")
    assert [o.get_name() for o in objects] == ["obj_000001", "obj_000002"]
    first = objects[0]
    assert first.get_cp("category_id") == 1 and first.get_cp("bop_dataset_name") == "lm"
    assert first.get_cp("is_bop_object") is True and first.get_cp("model_path").endswith("obj_000001.ply")
    np.testing.assert_allclose(first.get_scale(), [0.001] * 3)
    np.testing.assert_allclose(np.ptp(first.get_bound_box(), axis=0), [0.06, 0.04, 0.03], atol=1e-9)
    assert first.get_materials()[-1].get_name() == "bop_lm_vertex_col_material"
    random.seed(3)
    drawn = bproc.loader.load_bop_objs(str(dataset), sample_objects=True, num_of_objs_to_sample=3,
                                       obj_instances_limit=2, move_origin_to_x_y_plane=True)
    assert len(drawn) == 3 and all(o.get_name().startswith("obj_00000") for o in drawn)
    materials = [m for o in [*objects, *drawn] for m in o.get_materials()]
    assert len(set(map(id, materials))) == len(materials)  # a duplicate gets copies of the materials
    assert min(o.get_bound_box()[:, 2].min() for o in drawn) == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(InputError, match="instances limit"):
        bproc.loader.load_bop_objs(str(dataset), sample_objects=True, num_of_objs_to_sample=5,
                                   obj_instances_limit=1)
    with pytest.raises(InputError, match="does not exist"):
        bproc.loader.load_bop_objs(str(tmp_path / "missing" / "lm"))


def test_bop_scene_replication_reproduces_the_scene_gt_poses(bproc, tmp_path):
    dataset = _bop(tmp_path)
    objects = bproc.loader.load_bop_scene(str(dataset), scene_id=1, object_model_unit="mm")
    assert bproc.utility.num_frames() == 2
    gt = json.loads((dataset / "test" / "000001" / "scene_gt.json").read_text())
    opencv = np.diag([1.0, -1.0, -1.0, 1.0])
    for frame in (0, 1):
        cam2world = bproc.camera.get_camera_pose(frame) @ opencv
        for obj, instance in zip(objects, gt[str(frame)]):
            m2c = np.linalg.inv(cam2world) @ obj.world_matrix(frame)
            np.testing.assert_allclose(m2c[:3, :3] / 0.001, np.reshape(instance["cam_R_m2c"], (3, 3)), atol=1e-9)
            np.testing.assert_allclose(m2c[:3, 3], np.asarray(instance["cam_t_m2c"]) * 0.001, atol=1e-9)
    np.testing.assert_allclose(bproc.camera.get_intrinsics_as_K_matrix(), [[500, 0, 300], [0, 510, 250], [0, 0, 1]],
                               atol=1e-6)


def test_bop_intrinsics_and_the_tless_principal_point(bproc, tmp_path):
    k, width, height = bproc.loader.load_bop_intrinsics(str(_bop(tmp_path)))
    assert (width, height) == (640, 480) and k[0, 2] == 300.0
    np.testing.assert_allclose(bproc.camera.get_intrinsics_as_K_matrix(), k, atol=1e-6)
    k, _, _ = bproc.loader.load_bop_intrinsics(str(_bop(tmp_path / "t", "tless")))
    assert (k[0, 2], k[1, 2]) == (320.0, 240.0)


def test_object_datasets_shapenet_pix3d_ikea(bproc, tmp_path):
    shapenet = tmp_path / "ShapeNetCore.v2"
    _box_obj(shapenet / "02691156" / "abc" / "models" / "model_normalized.obj", (0.4, 0.2, 0.6))
    (shapenet / "taxonomy.json").write_text(json.dumps([{"synsetId": "02691156", "children": []}]))
    obj = bproc.loader.load_shapenet(str(shapenet), used_synset_id="02691156")
    assert isinstance(obj, bproc.types.MeshObject)
    assert obj.get_cp("used_source_id") == "abc" and obj.get_cp("used_synset_id") == "02691156"
    np.testing.assert_allclose(obj.get_rotation_euler(), 0.0)
    box = obj.get_bound_box()
    np.testing.assert_allclose([box[:, 2].min(), np.ptp(box[:, 2]), np.ptp(box[:, 1])], [0.0, 0.2, 0.6], atol=1e-9)
    with pytest.raises(InputError, match="bproc.loader.load_shapenet: used_source_id: no model 'zzz'"):
        bproc.loader.load_shapenet(str(shapenet), used_synset_id="02691156", used_source_id="zzz")

    pix3d = tmp_path / "pix3d"
    _box_obj(pix3d / "model" / "bed" / "one" / "model.obj", (2.0, 0.5, 1.0))
    (pix3d / "pix3d.json").write_text(json.dumps([{"category": "bed", "model": "model/bed/one/model.obj"}]))
    beds = bproc.loader.load_pix3d("bed", str(pix3d))
    assert len(beds) == 1 and beds[0].get_cp("model_path").endswith("model.obj")

    ikea = tmp_path / "ikea"
    _box_obj(ikea / "IKEA" / "IKEA_table_LACK" / "lack.obj", (1.0, 0.5, 0.6), mtl=True)
    tables = bproc.loader.load_ikea(str(ikea), obj_categories="table")
    assert [t.get_name() for t in tables] == ["IKEA_table_LACK"]


def test_scenenet_and_front3d_take_a_label_mapping(bproc, tmp_path):
    mapping = bproc.utility.LabelIdMapping.from_dict({"void": 0, "wall": 1, "floor": 2, "bed": 4, "ceiling": 22,
                                                      "picture": 11, "otherstructure": 38})
    room = tmp_path / "scenenet" / "room.obj"
    room.parent.mkdir(parents=True)
    room.write_text("mtllib room.mtl\no Bed\nusemtl bed_01\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n"
                    "o ground\nusemtl floor_tiles\nv 0 0 0\nv 4 0 0\nv 4 0 4\nf 4 5 6\n")
    (tmp_path / "scenenet" / "room.mtl").write_text("newmtl bed_01\nKd 1 1 1\nnewmtl floor_tiles\nKd 1 1 1\n")
    for folder in ("bed", "floortiles"):
        (tmp_path / "tex" / folder).mkdir(parents=True)
        Image.new("RGB", (4, 4)).save(tmp_path / "tex" / folder / "a.jpg")
    objects = bproc.loader.load_scenenet(str(room), str(tmp_path / "tex"), mapping)
    assert [(o.get_name(), o.get_cp("category_id")) for o in objects] == [("Bed", 4), ("floor", 2)]
    assert all(o.get_cp("is_scene_net_obj") for o in objects)
    with pytest.raises(InputError, match="label_mapping must be a bproc.utility.LabelIdMapping"):
        bproc.loader.load_scenenet(str(room), str(tmp_path / "tex"), {"bed": 4})

    front = tmp_path / "front"
    (front / "textures").mkdir(parents=True)
    _box_obj(front / "models" / "jid1" / "raw_model.obj", (1.0, 0.5, 2.0))
    house = {"uid": "h",
             "material": [{"uid": "m", "texture": "", "normaltexture": "", "color": [200, 200, 200, 255]}],
             "mesh": [{"uid": "f", "type": "Floor", "material": "m", "xyz": [0, 0, 0, 4, 0, 0, 4, 0, 4],
                       "normal": [0, 1, 0] * 3, "uv": [0, 0, 1, 0, 1, 1], "faces": [0, 2, 1]}],
             "furniture": [{"uid": "u1", "jid": "jid1", "category": "Bed"}],
             "scene": {"room": [{"instanceid": "Bedroom-1", "children": [
                 {"ref": "u1", "instanceid": "furniture/1", "pos": [1, 0, 2], "rot": [0, 0, 0, 1],
                  "scale": [1, 1, 1]}]}]}}
    (front / "house.json").write_text(json.dumps(house))
    front_mapping = bproc.utility.LabelIdMapping.from_dict({"void": 0, "floor": 1, "bed": 2})
    loaded = bproc.loader.load_front3d(str(front / "house.json"), str(front / "models"), str(front / "textures"),
                                       front_mapping)
    by_name = {o.get_name(): o for o in loaded}
    assert by_name["Floor"].get_cp("category_id") == 1 and not by_name["Floor"].has_cp("uid")
    bed = by_name["Bed.001"]  # the SceneNet room holds a "Bed"
    assert bed.get_cp("category_id") == 2 and bed.get_cp("3D_future_type") == "Object"
    assert bed.get_cp("is_used") is True and bed.get_cp("room_id") == 0 and bed.get_cp("is_3d_front") is True
    np.testing.assert_allclose(bed.get_local2world_mat()[:3, 3], [1.0, 2.0, 0.0], atol=1e-9)


def test_replica_and_matterport3d(bproc, tmp_path):
    room = trimesh.creation.box(extents=[4, 3, 2.5])
    room.visual.vertex_colors = np.tile([180, 170, 160, 255], (len(room.vertices), 1))
    (tmp_path / "replica" / "office_1").mkdir(parents=True)
    room.export(tmp_path / "replica" / "office_1" / "mesh.ply")
    objects = bproc.loader.load_replica(str(tmp_path / "replica"), "office_1", use_smooth_shading=True)
    assert len(objects) == 1 and objects[0].get_cp("model_path").endswith("mesh.ply")

    house = tmp_path / "mp" / "v1" / "scans" / "h1" / "h1.obj"
    house.parent.mkdir(parents=True)
    house.write_text("o house\nv 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 2\nv 0 4 2\nv 1 1 0.7\nv 2 1 0.7\nv 2 2 0.7\n"
                     "f 1 2 3\nf 1 3 4\nf 1 4 6\nf 1 6 5\nf 7 8 9\n")
    rest, floor = bproc.loader.load_matterport3d(str(tmp_path / "mp"))
    assert floor.get_name() == "Surface" and rest.get_name() == "house"
    assert sum(len(p.faces) for p in floor.parts) == 2 and sum(len(p.faces) for p in rest.parts) == 3
    assert np.ptp(floor.get_bound_box()[:, 2]) == pytest.approx(0.0)
    material = rest.get_materials()[0].blender_obj
    assert material.emission_strength == 1.0 and not material.emission_hidden_from_camera
    with pytest.raises(InputError, match="does not appear"):
        bproc.loader.load_matterport3d(str(tmp_path / "mp"), used_house_id="nope")


def test_cc_and_haven_materials_textures_and_hdris(bproc, tmp_path):
    cc = tmp_path / "cc"
    for asset in ("Bricks001", "Foliage002", "Wood003", "Metal004"):
        (cc / asset).mkdir(parents=True)
        Image.new("RGB", (4, 4)).save(cc / asset / f"{asset}_2K_Color.jpg")
    Image.new("L", (4, 4)).save(cc / "Metal004" / "Metal004_2K_Opacity.jpg")
    names = [m.get_name() for m in bproc.loader.load_ccmaterials(str(cc))]
    assert names == ["Bricks001", "Wood003"]  # foliage is not among the default kinds, Metal004 is transparent
    loaded = bproc.loader.load_ccmaterials(str(cc), used_assets=["Foliage"], add_custom_properties={"cp_src": "cc"})
    assert [(m.get_name(), m.get_cp("is_cc_texture"), m.get_cp("asset_name"), m.get_cp("src")) for m in loaded] == \
        [("Foliage002", True, "Foliage002", "cc")]
    assert loaded[0].blender_obj.base_color_texture.endswith("Foliage002_2K_Color.jpg")
    all_of_them = bproc.loader.load_ccmaterials(str(cc), use_all_materials=True, skip_transparent_materials=False)
    assert len(all_of_them) == 4

    preloaded = bproc.loader.load_ccmaterials(str(cc), used_assets=["Wood"], add_custom_properties={"cp_x": 1},
                                              preload=True)
    cube = bproc.object.create_primitive("CUBE")
    cube.replace_materials(preloaded[0])
    assert bproc.loader.load_ccmaterials(str(cc), used_assets=["Wood"], add_custom_properties={"cp_x": 1},
                                         fill_used_empty_materials=True) == preloaded
    with pytest.raises(InputError, match="can not be done at the same time"):
        bproc.loader.load_ccmaterials(str(cc), preload=True, fill_used_empty_materials=True)

    haven = tmp_path / "haven"
    (haven / "textures" / "rock_01").mkdir(parents=True)
    Image.new("RGB", (4, 4)).save(haven / "textures" / "rock_01" / "rock_01_diff_2k.jpg")
    Image.new("L", (4, 4)).save(haven / "textures" / "rock_01" / "rock_01_rough_2k.jpg")
    rock = bproc.loader.load_haven_mat(str(haven), return_random_element=True)
    assert rock.get_name() == "rock_01" and rock.blender_obj.roughness_texture.endswith("rock_01_rough_2k.jpg")
    for name in ("b_sky", "a_sky"):
        (haven / "hdris" / name).mkdir(parents=True)
        (haven / "hdris" / name / f"{name}_2k.hdr").write_bytes(b"#?RADIANCE\n")
    random.seed(0)
    expected = random.Random(0).choice(sorted(str(p) for p in (haven / "hdris").glob("*/*.hdr")))
    assert bproc.loader.get_random_world_background_hdr_img_path_from_haven(str(haven)) == expected

    textures = bproc.loader.load_texture(str(cc / "Bricks001"))
    assert [t.name for t in textures] == ["ct_Bricks001_2K_Color.jpg"] and textures[0].image.filepath.endswith(".jpg")
    assert bproc.loader.load_texture(str(cc / "Bricks001" / "Bricks001_2K_Color.jpg")) == []  # loaded before


URDF = """<?xml version="1.0"?>
<robot name="arm">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base">
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry><material name="grey"/></visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
  <joint name="j1" type="revolute">
    <origin xyz="0 0 0.5" rpy="0 0 1.5707963267948966"/>
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <visual><origin xyz="0.1 0 0"/><geometry><mesh filename="part.obj"/></geometry></visual>
  </link>
</robot>
"""


def test_urdf_links_at_the_zero_pose(bproc, tmp_path):
    (tmp_path / "arm.urdf").write_text(URDF)
    (tmp_path / "part.obj").write_text("o part\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    robot = bproc.loader.load_urdf(str(tmp_path / "arm.urdf"))
    # the robot is named first (BlenderProc's armature), so its link "arm" becomes "arm.001" as in Blender
    assert robot.get_name() == "arm" and [link.get_name() for link in robot.links] == ["base", "arm.001"]
    base, arm = robot.links
    assert arm.get_joint_type() == "revolute" and base.get_joint_type() is None
    assert arm.get_link_parent() is base and base.get_link_child() is arm
    visual = arm.get_visuals()[0]
    assert visual.get_name() == "arm_visual"
    np.testing.assert_allclose(visual.get_local2world_mat()[:3, 3], [0.0, 0.1, 0.5], atol=1e-9)
    np.testing.assert_allclose(np.ptp(base.get_visuals()[0].get_bound_box(), axis=0), [0.04, 0.04, 0.02], atol=1e-9)
    assert base.get_visuals()[0].get_materials()[0].get_principled_shader_value("Base Color") == [0.5, 0.5, 0.5, 1.0]
    assert base.get_collisions()[0].is_hidden() and base.get_inertial().is_hidden()
    assert not visual.is_hidden() and base.get_inertial().get_mass() == 2.0
    robot.set_ascending_category_ids()
    assert visual.get_cp("category_id") == 2
    assert robot.get_all_local2world_mats().shape == (1, 4, 4)
    robot.set_rotation_euler_fk(link=None, rotation_euler=0.5, mode="relative", frame=0)  # about j1's axis (z)
    turned = np.pi / 2 + 0.5
    np.testing.assert_allclose(visual.get_local2world_mat()[:3, 3], [0.1 * np.cos(turned), 0.1 * np.sin(turned), 0.5],
                               atol=1e-9)
    robot.remove_link_by_index(0)  # no joint: only leaves the list
    assert [link.get_name() for link in robot.links] == ["arm.001"] and base.is_valid()


def test_load_blend_argument_checks(bproc, tmp_path):
    with pytest.raises(InputError, match="No such object type: cube"):
        bproc.loader.load_blend(str(tmp_path / "x.blend"), obj_types=["cube"])
    with pytest.raises(InputError, match=r"load_blend\(obj_types=\['camera'\]\) is not supported"):
        bproc.loader.load_blend(str(tmp_path / "x.blend"), obj_types=["mesh", "camera"])
    with pytest.raises(InputError, match=r"load_blend\(data_blocks=\['materials'\]\) is not supported"):
        bproc.loader.load_blend(str(tmp_path / "x.blend"), data_blocks=["objects", "materials"])


def _bpy() -> bool:
    from hybridgen.errors import SystemSetupError
    from hybridgen.io import blend_loader

    try:
        blend_loader.bpy_python()
        return True
    except SystemSetupError:
        return False


@pytest.mark.skipif(not _bpy(), reason="no Python with bpy (make bpy-venv)")
def test_load_blend_gives_blenders_objects_in_the_files_order(bproc, tmp_path):
    import subprocess

    from hybridgen.io.blend_loader import bpy_python

    out = tmp_path / "scene.blend"
    done = subprocess.run([str(bpy_python()), str(REPO / "tools" / "make_blend_fixture.py"), str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    bproc.object.create_primitive("CUBE").set_name("Box")
    entities = bproc.loader.load_blend(str(out))
    assert [(type(e).__name__, e.get_name()) for e in entities] == [
        ("MeshObject", "Box.001"), ("MeshObject", "Ground"), ("Entity", "Target")]
    box = entities[0]
    assert box.get_cp("category_id") == 7 and box.get_cp("label") == "box" and not box.has_cp("source_path")
    np.testing.assert_allclose(box.get_location(), [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(box.get_rotation_euler(), [0, 0, 0.3], atol=1e-6)
    assert box.get_materials()[0].get_principled_shader_value("Roughness") == pytest.approx(0.35)
    lights = bproc.loader.load_blend(str(out), obj_types="light", name_regrex="La.*")
    assert [(type(e).__name__, e.get_name(), e.get_energy()) for e in lights] == [("Light", "Lamp", 500.0)]


def test_load_obj_import_axes(bproc, tmp_path):
    (tmp_path / "tri.obj").write_text("o tri\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    default = bproc.loader.load_obj(str(tmp_path / "tri.obj"))[0]
    np.testing.assert_allclose(default.get_rotation_euler(), [np.pi / 2, 0, 0], atol=1e-9)
    as_stored = bproc.loader.load_obj(str(tmp_path / "tri.obj"), forward_axis="Y", up_axis="Z")[0]
    np.testing.assert_allclose(as_stored.get_local2world_mat(), np.eye(4), atol=1e-9)
    with pytest.raises(InputError, match="must differ"):
        bproc.loader.load_obj(str(tmp_path / "tri.obj"), forward_axis="Z", up_axis="NEGATIVE_Z")


def test_upper_region_over_a_flat_floor(bproc):
    """A plane's (or Matterport3D floor's) bounding box has no height: its top face is the one sampled on."""
    plane = bproc.object.create_primitive("PLANE", scale=[2, 2, 1])
    point = bproc.sampler.upper_region([plane], min_height=1.5, max_height=1.8)
    assert np.all(np.isfinite(point)) and 1.5 <= point[2] <= 1.8 and np.all(np.abs(point[:2]) <= 2.0)
