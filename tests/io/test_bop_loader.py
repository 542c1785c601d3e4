"""``loader.BopLoader`` on a BOP dataset this test writes by hand (PLY models in mm with vertex colours,
models_info.json, camera.json, a test scene's scene_gt.json / scene_camera.json with known poses).

The oracle is independent of hybridgen: trimesh ray casting of the dataset's own meshes, posed by each image's
``cam_R_m2c`` / ``cam_t_m2c`` in that image's camera frame, through the pixel centres (integer coordinates, as
BOP and OpenCV count them) of the dataset's ``cam_K``. Replicating the scene and rendering labels must give the same depth and the same per-object masks.
"""
from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.config.config_file import load_config
from hybridgen.errors import ConfigError
from hybridgen.run.pipeline import build_modules, execute
from tests.conftest import silhouette

K = np.array([[190.0, 0.0, 83.0], [0.0, 185.0, 57.5], [0.0, 0.0, 1.0]])  # off-centre principal point, fx != fy
WIDTH, HEIGHT = 160, 120
SCENE_ID = 7


def _models() -> dict[int, trimesh.Trimesh]:
    """Three models in millimetres, each with its own vertex colour (as BOP's PLYs carry them)."""
    box = trimesh.creation.box([60.0, 40.0, 30.0])
    cylinder = trimesh.creation.cylinder(radius=20.0, height=50.0, sections=24)
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=25.0)
    sphere.apply_translation([5.0, -3.0, 8.0])  # a model origin that is not its centre
    models = {1: box, 2: cylinder, 3: sphere}
    for obj_id, mesh in models.items():
        mesh.visual.vertex_colors = np.tile([60 * obj_id, 200 - 50 * obj_id, 90, 255], (len(mesh.vertices), 1))
    return models


def _look_at_opencv(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """OpenCV cam2world (x right, y down, z forward) at ``eye`` looking at ``target``; world z up."""
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = eye
    return pose


# Instances of the scene: (obj_id, model-to-world pose in mm). Model 2 appears twice.
def _instances() -> list[tuple[int, np.ndarray]]:
    out = []
    for obj_id, loc, rot in [(1, [0, 0, 0], [0.2, 0.1, 0.5]), (2, [70, 20, 10], [1.2, 0.0, 0.3]),
                             (3, [-50, 40, 20], [0.0, 0.4, 0.0]), (2, [10, -60, -5], [0.0, 0.0, 1.0])]:
        pose = trimesh.transformations.euler_matrix(*rot)
        pose[:3, 3] = loc
        out.append((obj_id, pose))
    return out


CAMERA_EYES = [[170.0, -220.0, 140.0], [-200.0, -170.0, 90.0], [30.0, 240.0, 170.0]]


def make_dataset(root: Path, name: str = "sd") -> Path:
    """Write a BOP dataset ``root/name`` by hand and return its folder."""
    dataset = root / name
    models = _models()
    for folder, grow in (("models", 1.0), ("models_cad", 2.0)):  # models_cad: the same shapes, twice as big
        (dataset / folder).mkdir(parents=True)
        info = {}
        for obj_id, mesh in models.items():
            mesh = mesh.copy()
            mesh.apply_scale(grow)
            mesh.export(dataset / folder / f"obj_{obj_id:06d}.ply")
            low, high = mesh.bounds
            info[str(obj_id)] = {"diameter": float(np.linalg.norm(high - low)), "min_x": low[0], "min_y": low[1],
                                 "min_z": low[2], "size_x": high[0] - low[0], "size_y": high[1] - low[1],
                                 "size_z": high[2] - low[2]}
        (dataset / folder / "models_info.json").write_text(json.dumps(info))
    (dataset / "camera.json").write_text(json.dumps({"cx": K[0, 2], "cy": K[1, 2], "fx": K[0, 0], "fy": K[1, 1],
                                                     "width": WIDTH, "height": HEIGHT, "depth_scale": 1.0}))
    scene_dir = dataset / "test" / f"{SCENE_ID:06d}"
    scene_dir.mkdir(parents=True)
    scene_gt, scene_camera = {}, {}
    for image_id, eye in enumerate(CAMERA_EYES):
        world2cam = np.linalg.inv(_look_at_opencv(np.array(eye), np.zeros(3)))
        scene_gt[str(image_id)] = []
        for obj_id, m2w in _instances():
            m2c = world2cam @ m2w
            scene_gt[str(image_id)].append({"cam_R_m2c": m2c[:3, :3].ravel().tolist(),
                                            "cam_t_m2c": m2c[:3, 3].tolist(), "obj_id": obj_id})
        scene_camera[str(image_id)] = {"cam_K": K.ravel().tolist(), "depth_scale": 1.0}
    (scene_dir / "scene_gt.json").write_text(json.dumps(scene_gt))
    (scene_dir / "scene_camera.json").write_text(json.dumps(scene_camera))
    return dataset


def _raycast_gt(instances: list[dict], scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Depth (camera z) and instance index (+1; 0 = nothing) of one image from its scene_gt entries."""
    models = _models()
    meshes, owners = [], []
    for index, inst in enumerate(instances):
        m2c = np.eye(4)
        m2c[:3, :3] = np.reshape(inst["cam_R_m2c"], (3, 3))
        m2c[:3, 3] = np.asarray(inst["cam_t_m2c"])
        mesh = models[inst["obj_id"]].copy()
        mesh.apply_transform(m2c)
        mesh.apply_scale(scale)
        meshes.append(mesh)
        owners.append(np.full(len(mesh.faces), index + 1))
    world = trimesh.util.concatenate(meshes)
    owner = np.concatenate(owners)
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH]
    pixels = np.stack([u.ravel(), v.ravel(), np.ones(u.size)], axis=1)  # centres at integers (BOP, OpenCV)
    dirs = pixels @ np.linalg.inv(K).T
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    origins = np.zeros_like(dirs)
    locations, ray_index, tri_index = world.ray.intersects_location(origins, dirs, multiple_hits=False)
    depth = np.zeros(len(dirs))
    ids = np.zeros(len(dirs), np.int64)
    depth[ray_index] = locations[:, 2]
    ids[ray_index] = owner[tri_index]
    return depth.reshape(HEIGHT, WIDTH), ids.reshape(HEIGHT, WIDTH)


def _load(tmp_path: Path, **loader: object) -> hg.Scene:
    """Run main.Initializer + loader.BopLoader with ``loader`` keys; return the scene."""
    config = {"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.BopLoader", "config": loader}]}
    path = tmp_path / "bop_loader.yaml"
    path.write_text(json.dumps(config))
    loaded = load_config(path)
    return execute(loaded, build_modules(loaded)).scene


@pytest.mark.parametrize("mm2m", [True, False])
def test_replicated_scene_renders_its_own_ground_truth(tmp_path, gl_context, mm2m):
    dataset = make_dataset(tmp_path)
    scene = _load(tmp_path, bop_dataset_path=str(dataset), split="test", scene_id=SCENE_ID, mm2m=mm2m)
    scale = 0.001 if mm2m else 1.0
    gt = json.loads((dataset / "test" / f"{SCENE_ID:06d}" / "scene_gt.json").read_text())
    assert [o.category_id for o in scene.objects] == [1, 2, 3, 2]  # category_id = obj_id, one object an instance
    assert [o.name for o in scene.objects] == ["obj_000001", "obj_000002", "obj_000003", "obj_000002.001"]
    assert {o.attributes["bop_dataset_name"] for o in scene.objects} == {"sd"}
    assert len(scene.camera) == len(CAMERA_EYES)
    np.testing.assert_allclose(scene.camera.intrinsics.K, K)
    assert scene.camera.intrinsics.resolution == (WIDTH, HEIGHT)
    view = hg.RasterView(scene, depth_background=0.0)
    for image_id, instances in gt.items():
        ours = view.render(scene.camera.keypoints[int(image_id)], ["depth", "instance_segmaps"])
        ref_depth, ref_index = _raycast_gt(instances, scale)
        to_index = {obj.instance_id: i + 1 for i, obj in enumerate(scene.objects)}
        our_index = np.vectorize(lambda i: to_index.get(int(i), 0))(ours["instance_segmaps"])
        edge = silhouette(ref_index)
        for index in range(1, len(instances) + 1):  # every object's mask, pixel by pixel off its silhouette
            ref_mask, our_mask = ref_index == index, our_index == index
            assert ref_mask.sum() > 30, (image_id, index)  # every object is visible in every image
            assert not ((ref_mask != our_mask) & ~edge).any(), (image_id, index)
            assert (ref_mask != our_mask).sum() <= 0.02 * ref_mask.sum()  # measured: 0 or 1 pixel
            both = ref_mask & our_mask
            np.testing.assert_allclose(ours["depth"][both], ref_depth[both], rtol=2e-5, atol=2e-5 * scale)
        assert not ((our_index > 0) != (ref_index > 0))[~edge].any()  # background where the dataset has none


def test_objects_without_a_scene_listed_all_and_sampled(tmp_path):
    dataset = make_dataset(tmp_path)
    listed = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[3, 1], mm2m=True)
    assert [(o.name, o.category_id) for o in listed.objects] == [("obj_000003", 3), ("obj_000001", 1)]
    np.testing.assert_allclose(listed.camera.intrinsics.K, K)  # intrinsics of camera.json
    box = listed.objects[1].world_vertices()
    np.testing.assert_allclose(box.max(axis=0) - box.min(axis=0), [0.06, 0.04, 0.03], atol=1e-9)  # mm -> m

    everything = _load(tmp_path, bop_dataset_path=str(dataset))  # no obj_ids: every model in models_info.json
    assert [o.category_id for o in everything.objects] == [1, 2, 3]
    box_mm = everything.objects[0].world_vertices()  # mm2m off: millimetres as stored
    np.testing.assert_allclose(box_mm.max(axis=0) - box_mm.min(axis=0), [60, 40, 30], atol=1e-6)

    cad = _load(tmp_path, bop_dataset_path=str(dataset), model_type="cad", obj_ids=[1], mm2m=True)
    box_cad = cad.objects[0].world_vertices()  # models_cad/ holds the twice as big models
    np.testing.assert_allclose(box_cad.max(axis=0) - box_cad.min(axis=0), [0.12, 0.08, 0.06], atol=1e-9)

    sampled = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[1, 2, 3], sample_objects=True,
                    num_of_objs_to_sample=5, obj_instances_limit=2, mm2m=True)
    counts = Counter(o.category_id for o in sampled.objects)
    assert sum(counts.values()) == 5 and max(counts.values()) <= 2 and set(counts) <= {1, 2, 3}
    again = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[1, 2, 3], sample_objects=True,
                  num_of_objs_to_sample=5, obj_instances_limit=2, mm2m=True)
    assert [o.category_id for o in again.objects] == [o.category_id for o in sampled.objects]  # same seed

    with_replacement = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[2], sample_objects=True,
                             num_of_objs_to_sample=4)
    assert [o.name for o in with_replacement.objects] == ["obj_000002", "obj_000002.001", "obj_000002.002",
                                                          "obj_000002.003"]


def test_instance_limit_too_small_for_the_sample_is_an_input_error(tmp_path):
    dataset = make_dataset(tmp_path)
    with pytest.raises(ConfigError, match="obj_instances_limit.*cannot give 4 objects"):
        _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[1, 2], sample_objects=True,
              num_of_objs_to_sample=4, obj_instances_limit=1)


def _run_error(tmp_path: Path, run_cli, loader: dict) -> str:
    config = tmp_path / "bad_bop.yaml"
    config.write_text(json.dumps({"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": "<args:0>"}}},
        {"module": "loader.BopLoader", "config": loader},
        {"module": "renderer.SegMapRenderer", "config": {"map_by": "instance"}},
        {"module": "writer.Hdf5Writer", "config": {}}]}))
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert not [p for p in out.rglob("*") if p.is_file() and not p.name.startswith(".")] if out.exists() else True
    return lines[0]


def test_bad_datasets_fail_with_one_line(tmp_path, run_cli, gl_context):
    dataset = make_dataset(tmp_path)
    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(tmp_path / "nope")})
    assert "module 'loader.BopLoader' (#1), key 'bop_dataset_path': BOP dataset folder not found" in line
    assert str(tmp_path / "nope") in line

    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(dataset), "obj_ids": [1, 99]})
    assert "key 'obj_ids': obj_id 99 is not a model of" in line and "models_info.json" in line

    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(dataset), "scene_id": 3})
    assert "key 'scene_id'" in line and str(dataset / "test" / "000003") in line

    scene_camera = dataset / "test" / f"{SCENE_ID:06d}" / "scene_camera.json"
    scene_camera.write_text(json.dumps({"0": {"depth_scale": 1.0}}))  # no cam_K
    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(dataset), "scene_id": SCENE_ID})
    assert "key 'scene_id': malformed BOP scene files" in line and "cam_K" in line

    gt = dataset / "test" / f"{SCENE_ID:06d}" / "scene_gt.json"
    gt.write_text(gt.read_text()[:-20])  # cut short
    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(dataset), "scene_id": SCENE_ID})
    assert f"cannot read BOP file '{gt}'" in line and "key 'scene_id'" in line

    (dataset / "models" / "models_info.json").write_text("{1: ")
    line = _run_error(tmp_path, run_cli, {"bop_dataset_path": str(dataset)})
    assert f"cannot read BOP file '{dataset / 'models' / 'models_info.json'}'" in line


def test_listed_ids_need_only_their_model_files(tmp_path):
    dataset = make_dataset(tmp_path)
    (dataset / "models" / "models_info.json").unlink()
    scene = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[2], mm2m=True)
    assert [o.category_id for o in scene.objects] == [2]
    with pytest.raises(ConfigError, match="obj_ids.*obj_id 4 has no model"):
        _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[2, 4])


TEXTURED_PLY = """ply
format ascii 1.0
comment TextureFile obj_000001.png
element vertex 3
property float x
property float y
property float z
property float texture_u
property float texture_v
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0
10 0 0 1 0
0 10 0 0 1
3 0 1 2
"""


def test_model_colours_vertex_colours_and_ycbv_style_textures(tmp_path):
    from PIL import Image

    dataset = make_dataset(tmp_path)
    scene = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[2])
    # hybridgen materials have one base colour: a model's (here uniform) vertex colour becomes it
    np.testing.assert_allclose(scene.objects[0].material.base_color, np.array([120, 100, 90, 255]) / 255)

    textured = tmp_path / "yc"  # a ycbv-like model: texture_u/texture_v and a 'comment TextureFile' image
    (textured / "models").mkdir(parents=True)
    (textured / "models" / "obj_000001.ply").write_text(TEXTURED_PLY)
    Image.fromarray(np.full((4, 4, 3), [10, 200, 30], np.uint8)).save(textured / "models" / "obj_000001.png")
    (textured / "models" / "models_info.json").write_text(json.dumps({"1": {"diameter": 14.1}}))
    (textured / "camera.json").write_text(json.dumps({"cx": 80, "cy": 60, "fx": 100, "fy": 100, "width": 160,
                                                      "height": 120}))
    obj = _load(tmp_path, bop_dataset_path=str(textured)).objects[0]
    assert obj.attributes["bop_dataset_name"] == "yc" and obj.category_id == 1
    np.testing.assert_allclose(obj.uvs, [[0, 0], [1, 0], [0, 1]])
    assert tuple(obj.material.base_color_texture[0, 0, :3]) == (10, 200, 30)


def test_tless_layout_defaults_and_principal_point(tmp_path):
    dataset = make_dataset(tmp_path, name="tless")  # camera.json's cx, cy are off-centre
    (dataset / "camera.json").rename(dataset / "camera_primesense.json")  # T-LESS as published
    (dataset / "test").rename(dataset / "test_primesense")
    scene = _load(tmp_path, bop_dataset_path=str(dataset), obj_ids=[1], mm2m=True)
    np.testing.assert_allclose(scene.camera.intrinsics.K, [[K[0, 0], 0, WIDTH / 2], [0, K[1, 1], HEIGHT / 2],
                                                           [0, 0, 1]])  # as BlenderProc: the image centre
    box = scene.objects[0].world_vertices()  # model_type '' is T-LESS's CAD models (models_cad: twice as big)
    np.testing.assert_allclose(box.max(axis=0) - box.min(axis=0), [0.12, 0.08, 0.06], atol=1e-9)
    replicated = _load(tmp_path, bop_dataset_path=str(dataset), scene_id=SCENE_ID)  # from test_primesense/
    np.testing.assert_allclose(replicated.camera.intrinsics.K, K)  # scenes keep their cam_K
    assert len(replicated.camera) == len(CAMERA_EYES)
    with pytest.raises(ConfigError, match="key 'cam_type': BOP camera file not found: .*camera_kinect.json'$"):
        _load(tmp_path, bop_dataset_path=str(dataset), cam_type="kinect")
    with pytest.raises(ConfigError, match="key 'model_type': BOP models folder not found: .*models_reconst'$"):
        _load(tmp_path, bop_dataset_path=str(dataset), model_type="reconst")  # named types do not fall back
    (dataset / "camera_primesense.json").write_text(json.dumps({"fx": 100.0}))
    with pytest.raises(ConfigError, match="key 'cam_type': the BOP camera file needs numbers"):
        _load(tmp_path, bop_dataset_path=str(dataset))


def test_replicated_scene_written_by_the_bop_writer_is_the_scene_again(tmp_path):
    """Closed loop in BOP's own format: load scene N, render, write with writer.BopWriter; the written
    depth PNGs, visible masks, scene_gt and cam_K are the input scene's (depth against the ray-cast oracle)."""
    from PIL import Image

    from hybridgen.run.pipeline import run_config

    dataset = make_dataset(tmp_path)
    config = tmp_path / "replicate.yaml"
    config.write_text(json.dumps({"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.BopLoader", "config": {"bop_dataset_path": str(dataset), "scene_id": SCENE_ID,
                                                  "mm2m": True}},
        {"module": "renderer.RgbRenderer", "config": {"samples": 1, "render_depth": True, "map_by": ["instance"]}},
        {"module": "writer.BopWriter", "config": {"dataset": "sd", "depth_scale": 0.1}}]}))
    run_config(config, [])
    scene_in = dataset / "test" / f"{SCENE_ID:06d}"
    scene_out = tmp_path / "out" / "bop_data" / "sd" / "train_pbr" / "000000"
    gt_in = json.loads((scene_in / "scene_gt.json").read_text())
    gt_out = json.loads((scene_out / "scene_gt.json").read_text())
    cameras_out = json.loads((scene_out / "scene_camera.json").read_text())
    assert sorted(gt_out, key=int) == sorted(gt_in, key=int)
    for image_id, instances in gt_in.items():
        assert [i["obj_id"] for i in gt_out[image_id]] == [i["obj_id"] for i in instances]
        for inst_in, inst_out in zip(instances, gt_out[image_id]):
            np.testing.assert_allclose(inst_out["cam_R_m2c"], inst_in["cam_R_m2c"], atol=1e-6)
            np.testing.assert_allclose(inst_out["cam_t_m2c"], inst_in["cam_t_m2c"], atol=1e-3)
        np.testing.assert_allclose(cameras_out[image_id]["cam_K"], K.ravel())
        ref_depth_mm, ref_index = _raycast_gt(instances, 1.0)
        depth_mm = np.asarray(Image.open(scene_out / "depth" / f"{int(image_id):06d}.png"), np.float64) * 0.1
        edge = silhouette(ref_index)
        inside = (ref_index > 0) & ~edge
        np.testing.assert_allclose(depth_mm[inside], ref_depth_mm[inside], atol=0.051 + 2e-5 * 300)
        assert not depth_mm[(ref_index == 0) & ~edge].any()  # 0 where the dataset sees nothing
        for gt_id in range(len(instances)):
            visible = np.asarray(Image.open(scene_out / "mask_visib" / f"{int(image_id):06d}_{gt_id:06d}.png")) > 0
            assert not (visible != (ref_index == gt_id + 1))[~edge].any(), (image_id, gt_id)
