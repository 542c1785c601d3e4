"""camera.Front3DCameraSampler and camera.ReplicaCameraSampler on stand-ins in the datasets' layouts: every camera
stands inside a used room, straight above that room's floor (checked with trimesh's own ray caster), at the
configured height above it, passes the distance checks (rays cast independently through pixel centres of the
check image), and the same seed gives the same poses."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from hybridgen.errors import ConfigError, InputError
from hybridgen.sampling.camera_sampling import check_intrinsics
from tests.config.test_blenderproc_modules import run_config_text

MAPPING = "id,name\n0,void\n1,floor\n2,wallinner\n3,ceiling\n4,bed\n5,lamp\n6,sofa\n"


def _box_obj(path: Path, size: tuple[float, float, float]) -> None:
    """A box OBJ in file axes (y up) standing on y = 0, centred on x and z."""
    path.parent.mkdir(parents=True, exist_ok=True)
    x, y, z = size[0] / 2, size[1], size[2] / 2
    corners = [(a, b, c) for a in (-x, x) for b in (0, y) for c in (-z, z)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    path.write_text("\n".join([f"v {a} {b} {c}" for a, b, c in corners] +
                              [f"f {a} {b} {c} {d}" for a, b, c, d in quads]) + "\n")
    Image.new("RGB", (2, 2), (128, 128, 128)).save(path.parent / "texture.png")


def _quads(corners: list[tuple[float, float, float]], flip: bool = False) -> dict:
    """A 3D-FRONT mesh entry of quads (4 corners each, 3D-FRONT axes: y up)."""
    faces = []
    for q in range(len(corners) // 4):
        a, b, c, d = 4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3
        faces += [a, c, b, a, d, c] if flip else [a, b, c, a, c, d]
    return {"xyz": [v for corner in corners for v in corner], "faces": faces,
            "uv": [0, 0, 1, 0, 1, 1, 0, 1] * (len(corners) // 4)}


def _walls(x0: float, x1: float, z0: float, z1: float, height: float) -> list[tuple[float, float, float]]:
    return [(x0, 0, z0), (x1, 0, z0), (x1, height, z0), (x0, height, z0),
            (x1, 0, z0), (x1, 0, z1), (x1, height, z1), (x1, height, z0),
            (x1, 0, z1), (x0, 0, z1), (x0, height, z1), (x1, height, z1),
            (x0, 0, z1), (x0, 0, z0), (x0, height, z0), (x0, height, z1)]


@pytest.fixture
def house(tmp_path: Path) -> dict[str, str]:
    """Room A: an L-shaped floor (x 0..4, y 0..2 plus x 0..2, y 2..3) with a bed, a sofa and a lamp; room B
    (x 5..8, y 0..3) with one lamp; both walled and ceiled, 2.8 m high (3D-FRONT axes: y up, so file z = world y)."""
    models = tmp_path / "3D-FUTURE-model"
    _box_obj(models / "jid-bed" / "raw_model.obj", (1.2, 0.5, 0.8))
    _box_obj(models / "jid-sofa" / "raw_model.obj", (0.8, 0.7, 0.6))
    _box_obj(models / "jid-lamp" / "raw_model.obj", (0.2, 1.2, 0.2))
    (tmp_path / "3D-FRONT-texture").mkdir()
    floor_a = _quads([(0, 0, 0), (4, 0, 0), (4, 0, 2), (0, 0, 2), (0, 0, 2), (2, 0, 2), (2, 0, 3), (0, 0, 3)], True)
    floor_b = _quads([(5, 0, 0), (8, 0, 0), (8, 0, 3), (5, 0, 3)], True)
    ceiling = _quads([(0, 2.8, 0), (4, 2.8, 0), (4, 2.8, 3), (0, 2.8, 3), (5, 2.8, 0), (8, 2.8, 0), (8, 2.8, 3),
                      (5, 2.8, 3)])
    walls = _quads(_walls(0, 4, 0, 3, 2.8) + _walls(5, 8, 0, 3, 2.8))
    material = {"uid": "m", "texture": "", "normaltexture": "", "color": [200, 200, 200, 255]}

    def child(ref: str, x: float, y: float) -> dict:
        return {"ref": ref, "instanceid": f"furniture/{ref}-{x}", "pos": [x, 0.0, y], "rot": [0, 0, 0, 1],
                "scale": [1, 1, 1]}

    data = {
        "uid": "house", "material": [material],
        "mesh": [{"uid": "floor-a", "type": "Floor", "material": "m", **floor_a},
                 {"uid": "floor-b", "type": "Floor", "material": "m", **floor_b},
                 {"uid": "walls", "type": "WallInner", "material": "m", **walls},
                 {"uid": "ceiling", "type": "Ceiling", "material": "m", **ceiling}],
        "furniture": [{"uid": "bed", "jid": "jid-bed", "category": "Bed"},
                      {"uid": "sofa", "jid": "jid-sofa", "category": "Sofa"},
                      {"uid": "lamp", "jid": "jid-lamp", "title": "lamp/floor lamp"}],
        "scene": {"room": [{"instanceid": "Bedroom-1", "children": [child("bed", 1.0, 1.0), child("sofa", 3.2, 1.0),
                                                                     child("lamp", 0.5, 2.6)]},
                           {"instanceid": "Storage-2", "children": [child("lamp", 7.5, 0.5)]}]},
    }
    (tmp_path / "house.json").write_text(json.dumps(data))
    (tmp_path / "mapping.csv").write_text(MAPPING)
    return {"json_path": str(tmp_path / "house.json"), "3D_future_model_path": str(models),
            "3D_front_texture_path": str(tmp_path / "3D-FRONT-texture"), "mapping_file": str(tmp_path / "mapping.csv")}


def _front_run(tmp_path: Path, house: dict[str, str], seed: int = 3, samples: int = 8, **sampler):
    entry = {"number_of_samples": samples, "proximity_checks": {"min": 0.5},
             "location": {"provider": "sampler.Uniform3d", "min": [0, 0, 1.4], "max": [0, 0, 1.8]},
             "rotation": {"value": {"provider": "sampler.Uniform3d", "min": [1.2217, 0, 0], "max": [1.338, 0, 6.283185307]}}}
    return run_config_text(tmp_path, json.dumps({"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}, "seed": seed}},
        {"module": "loader.Front3DLoader", "config": house},
        {"module": "camera.Front3DCameraSampler", "config": {
            "intrinsics": {"resolution_x": 64, "resolution_y": 48}, "cam_poses": [entry], **sampler}}]}))


def _first_hit_below(scene, point: np.ndarray):
    """(object, hit z) of trimesh's ray cast straight down from ``point`` over every scene object."""
    best = (None, -np.inf)
    for obj in scene.objects:
        mesh = trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False)
        hits, _, _ = mesh.ray.intersects_location([point + [0, 0, 1e-7]], [[0, 0, -1.0]])
        for hit in hits:
            if hit[2] > best[1]:
                best = (obj, float(hit[2]))
    return best


def _check_distances(scene, cam2world: np.ndarray, minimum: float) -> None:
    """Rays through every 4th pixel centre of the 64 px check image (trimesh): nothing closer than ``minimum``."""
    intr = check_intrinsics(scene.camera.intrinsics, 64)
    rays = intr.pixel_rays()[::4, ::4].reshape(-1, 3)
    directions = rays @ cam2world[:3, :3].T
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origins = np.repeat(cam2world[None, :3, 3], len(directions), axis=0)
    for obj in scene.objects:
        mesh = trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False)
        hits, index, _ = mesh.ray.intersects_location(origins, directions)
        if len(hits):
            assert np.linalg.norm(hits - origins[index], axis=1).min() >= minimum - 1e-6, obj.name


def test_front3d_cameras_stand_in_furnished_rooms_above_their_floor(tmp_path, house):
    context = _front_run(tmp_path, house)
    scene = context.scene
    floor_a, floor_b = (next(o for o in scene.objects if o.attributes["uid"] == uid) for uid in ("floor-a", "floor-b"))
    poses = scene.camera.keypoints
    assert len(poses) == 8
    for pose in poses:
        below, height = _first_hit_below(scene, pose[:3, 3])
        assert below is floor_a  # room B holds one object (not more than 2): no camera there
        assert height == pytest.approx(0.0, abs=1e-9) and 1.4 <= pose[2, 3] <= 1.8
        assert not (pose[0, 3] > 2 and pose[1, 3] > 2)  # the L's missing corner is inside the bounding box
        _check_distances(scene, pose, 0.5)
        forward = pose[:3, 2]  # Blender's x rotation 1.22..1.34 rad: looking 13..20 deg below the horizon
        assert -np.sin(np.pi / 2 - 1.2217) - 1e-9 <= forward[2] <= -np.sin(np.pi / 2 - 1.338) + 1e-9
    again = _front_run(tmp_path, house)
    np.testing.assert_array_equal(np.array(again.scene.camera.keypoints), np.array(poses))
    other = _front_run(tmp_path, house, seed=4)
    assert not np.allclose(np.array(other.scene.camera.keypoints), np.array(poses))
    assert floor_b.name.startswith("Floor")


def test_front3d_room_threshold_counts_objects_on_each_floor(tmp_path, house):
    context = _front_run(tmp_path, house, samples=30, amount_of_objects_needed_per_room=0)
    rooms = {_first_hit_below(context.scene, pose[:3, 3])[0].attributes["uid"] for pose in context.scene.camera.keypoints}
    assert rooms == {"floor-a", "floor-b"}  # more than 0 objects on each floor: both rooms get cameras
    # as BlenderProc counts: every 3D-FRONT object but walls and ceilings, by the ray from its origin - room A
    # holds its 3 pieces of furniture and room B's floor, whose origin (the world origin) lies on room A's floor
    with pytest.raises(InputError, match=r"no room has more than 4 objects standing on its floor \(Floor: 4, "
                                         r"Floor.001: 1\)"):
        _front_run(tmp_path, house, amount_of_objects_needed_per_room=4)
    with pytest.raises(ConfigError) as info:
        _front_run(tmp_path, house, amount_of_objects_needed_per_room=-1)
    assert info.value.key == "amount_of_objects_needed_per_room" and "\n" not in str(info.value)


# ---------------------------------------------------------------------------------------------- Replica
@pytest.fixture
def replica(tmp_path: Path) -> Path:
    """<tmp>/replica/office_1/mesh.ply: one mesh, a 6 x 5 x 2.8 m room (floor at z = 0) with a table, in Replica's
    layout; BlenderProc's height list at resources/replica/height_levels/office_1 lists the floor (0.0) and a
    level 5 m up that this scene has no floor at."""
    room = trimesh.creation.box(extents=[6, 5, 2.8])
    room.apply_translation([3.0, 2.5, 1.4])
    room.invert()
    table = trimesh.creation.box(extents=[1.2, 0.8, 0.75])
    table.apply_translation([2.0, 2.0, 0.375])
    mesh = trimesh.util.concatenate([room, table])
    mesh.visual.vertex_colors = np.tile([180, 170, 160, 255], (len(mesh.vertices), 1))
    (tmp_path / "replica" / "office_1").mkdir(parents=True)
    mesh.export(tmp_path / "replica" / "office_1" / "mesh.ply")
    levels = tmp_path / "resources" / "replica" / "height_levels" / "office_1"
    levels.mkdir(parents=True)
    (levels / "height_list_values.txt").write_text("[0.0, 5.0]")
    return tmp_path / "replica"


def _replica_config(tmp_path: Path, replica: Path, seed: int = 2, **sampler) -> str:
    return json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender/"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {
            "output_dir": str(tmp_path / "out"), "data_set_name": "office_1", "data_path": str(replica)}, "seed": seed}},
        {"module": "loader.ReplicaLoader", "config": {"use_smooth_shading": True}},
        {"module": "object.FloorExtractor", "config": {"selector": {"provider": "getter.Entity",
                                                                     "conditions": {"name": "mesh"}},
                                                        "compare_angle_degrees": 7.5, "compare_height": 0.15,
                                                        "name_for_split_obj": "floor"}},
        {"module": "camera.ReplicaCameraSampler", "config": {
            "intrinsics": {"resolution_x": 64, "resolution_y": 48, "pixel_aspect_x": 1.333333333},
            "cam_poses": [{"number_of_samples": 6, "clip_start": 0.01, "proximity_checks": {"min": 0.8},
                           "location": [0, 0, 1.55],
                           "rotation": {"value": {"provider": "sampler.Uniform3d", "min": [1.3734, 0, 0],
                                                  "max": [1.3734, 0, 6.283185307]}}}], **sampler}}]})


def test_replica_cameras_above_the_extracted_floor_at_a_listed_height(tmp_path, replica, monkeypatch):
    monkeypatch.chdir(tmp_path)  # BlenderProc runs from its checkout: resources/ is found from there
    context = run_config_text(tmp_path, _replica_config(tmp_path, replica, is_replica_object=True))
    scene = context.scene
    floor = scene.by_name("floor")
    poses = scene.camera.keypoints
    assert len(poses) == 6
    for pose in poses:
        below, height = _first_hit_below(scene, pose[:3, 3])
        assert below is floor and height == pytest.approx(0.0, abs=1e-9)
        assert pose[2, 3] == pytest.approx(1.55)  # the 5 m level has no floor below it: never accepted
        _check_distances(scene, pose, 0.8)
    # pixel_aspect_x 4/3 as Blender: the fov spans the width, pixels 4/3 as wide as high
    K = scene.camera.intrinsics.K
    assert K[0, 0] == pytest.approx(64 / (2 * np.tan(0.691111 / 2))) and K[1, 1] == pytest.approx(K[0, 0] * 4 / 3)
    again = run_config_text(tmp_path, _replica_config(tmp_path, replica, is_replica_object=True))
    np.testing.assert_array_equal(np.array(again.scene.camera.keypoints), np.array(poses))
    # the same with the file named directly
    direct = run_config_text(tmp_path, _replica_config(
        tmp_path, replica, height_list_path="resources/replica/height_levels/office_1/height_list_values.txt"))
    np.testing.assert_array_equal(np.array(direct.scene.camera.keypoints), np.array(poses))


def test_replica_errors_name_the_key(tmp_path, replica, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigError) as info:
        run_config_text(tmp_path, _replica_config(tmp_path, replica))
    assert info.value.key == "height_list_path" and "\n" not in str(info.value)
    (tmp_path / "bad.txt").write_text("floor at zero")
    with pytest.raises(ConfigError, match="not a list of numbers") as info:
        run_config_text(tmp_path, _replica_config(tmp_path, replica, height_list_path=str(tmp_path / "bad.txt")))
    assert info.value.key == "height_list_path"
    with pytest.raises(ConfigError, match="no object named 'ground'") as info:
        run_config_text(tmp_path, _replica_config(tmp_path, replica, is_replica_object=True, floor_name="ground"))
    assert info.value.key == "floor_name" and "module 'camera.ReplicaCameraSampler'" in str(info.value)


def test_replica_v1_config_form(tmp_path, replica, monkeypatch):
    """BlenderProc 1.0's replica-dataset keys: PlyLoader with is_replica_object, FloorExtractor obj_name, the
    sampler's sample_amount, degrees and its height list folder (resources/replica-dataset)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "resources" / "replica").rename(tmp_path / "resources" / "replica-dataset")
    config = {"setup": {"blender_install_path": "/opt/blender/", "pip": ["h5py"]},
              "global": {"all": {"output_dir": str(tmp_path / "out"), "data_set_name": "office_1",
                                 "data_path": str(replica)}},
              "modules": [{"name": "main.Initializer", "config": {"seed": 5}},
                          {"name": "loader.PlyLoader", "config": {"is_replica_object": "True",
                                                                  "use_smooth_shading": "True",
                                                                  "use_ambient_occlusion": "True"}},
                          {"name": "manipulators.FloorExtractor", "config": {
                              "is_replica_object": "True", "obj_name": "mesh", "compare_angle_degrees": 7.5,
                              "compare_height": 0.15}},
                          {"name": "camera.ReplicaCameraSampler", "config": {
                              "is_replica_object": "True", "sqrt_number_of_rays": 10, "near_clipping": 0.01,
                              "sample_amount": 4, "resolution_x": 64, "resolution_y": 48,
                              "rotation_range_z": [0, 90], "proximity_checks": {"min": 0.8}}}]}
    context = run_config_text(tmp_path, json.dumps(config))
    scene = context.scene
    poses = scene.camera.keypoints
    assert len(poses) == 4 and scene.camera.intrinsics.width == 64
    for pose in poses:
        assert _first_hit_below(scene, pose[:3, 3])[0] is scene.by_name("floor")
        assert pose[2, 3] == pytest.approx(1.55)
        # Blender Euler XYZ (78.6901 deg, 0, z in 0..90 deg): the camera's -Z (its view) 11.31 deg below the
        # horizon, heading +Y turned about +Z by z: (-sin z, cos z)
        forward = pose[:3, 2]
        assert forward[2] == pytest.approx(-np.cos(np.radians(78.6901)), abs=1e-9)
        heading = np.degrees(np.arctan2(-forward[0], forward[1]))
        assert 0 <= heading <= 90
