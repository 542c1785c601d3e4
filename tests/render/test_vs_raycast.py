"""Labels against an independent engine: trimesh ray casting (Embree when installed) through pixel centres."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.scene.primitives import make_primitive
from tests.conftest import REPO, pixel_rays_world, silhouette


def _scene() -> hg.Scene:
    scene = hg.Scene()
    scene.add(make_primitive("cube", 12.0, name="room", category_id=1))  # closed; the camera is inside
    rng = np.random.default_rng(7)
    shapes = ["cube", "sphere", "cylinder", "cone", "torus"]
    for i in range(10):
        pose = hg.object_pose(rng.uniform([-2.5, -2.5, -1], [2.5, 2.5, 1.5]), rng.uniform(-np.pi, np.pi, 3),
                              rng.uniform(0.4, 1.2))
        scene.add(make_primitive(shapes[i % len(shapes)], 1.0, name=f"p{i}", category_id=2 + i % 3,
                                 local2world=pose))
    for obj in hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=9,
                               local2world=hg.object_pose([0.5, 0.5, 2.5], [0.3, 0.1, 0.0], 0.5)):
        scene.add(obj)
    # an open surface seen from both sides: a single quad
    scene.add(hg.MeshObject("sheet", [[-1, 3, -1], [1, 3, -1], [1, 3, 1], [-1, 3, 1]], [[0, 1, 2], [0, 2, 3]],
                            category_id=5))
    return scene


def _raycast(scene: hg.Scene, intr: hg.Intrinsics, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    meshes, owners = [], []
    for obj in scene.objects:
        meshes.append(trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False))
        owners.append(np.full(len(obj.faces), obj.instance_id))
    world = trimesh.util.concatenate(meshes)
    owner = np.concatenate(owners)
    dirs, cos_z = pixel_rays_world(intr, pose)
    origins = np.tile(pose[:3, 3], (len(dirs), 1))
    locations, ray_index, tri_index = world.ray.intersects_location(origins, dirs, multiple_hits=False)
    depth = np.full(len(dirs), np.inf)
    ids = np.zeros(len(dirs), np.int64)
    t = np.linalg.norm(locations - origins[ray_index], axis=1)
    depth[ray_index] = t * cos_z[ray_index]
    ids[ray_index] = owner[tri_index]
    return depth.reshape(intr.height, intr.width), ids.reshape(intr.height, intr.width)


@pytest.mark.parametrize("location,target", [
    ([4.5, -4.0, 3.0], [0, 0, 0]),
    ([-4.0, 3.5, 1.0], [0.5, 0, 0.3]),
    ([0.3, -5.0, 0.2], [0, 2, 0.5]),
    ([0.0, 0.0, 5.0], [0.2, 0.1, 0]),
])
def test_depth_and_ids_agree_with_ray_casting(gl_context, location, target):
    scene = _scene()
    intr = hg.Intrinsics.from_fov(1.1, 160, 120)
    pose = hg.look_at(location, target)
    out = hg.RasterView(scene).render(pose, ["depth", "instance_segmaps"], intrinsics=intr)
    ref_depth, ref_ids = _raycast(scene, intr, pose)
    ours_hit, ref_hit = out["instance_segmaps"] > 0, ref_ids > 0
    both = ours_hit & ref_hit
    assert both.mean() > 0.9  # the room surrounds the camera: nearly every pixel hits something
    disagree_hit = ours_hit != ref_hit
    assert disagree_hit.mean() < 1e-3
    assert not (disagree_hit & ~silhouette(ref_ids)).any()
    assert np.median(np.abs(out["depth"][both] - ref_depth[both])) <= 1e-5
    same_id = out["instance_segmaps"][both] == ref_ids[both]
    assert same_id.mean() >= 0.999
    assert len(np.unique(ref_ids)) >= 5  # the pose really sees several objects
