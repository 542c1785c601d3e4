"""Depth, distance, ids and NOCS against rays written out here from (u, v, K) and a slab ray-box intersection.

The object is an ASYMMETRIC box (extents 0.8 x 0.4 x 0.2, its local origin off-centre, scaled 1.3) so that a
mirrored axis, swapped channels, a missing scale or a half-pixel shift of the rays each change the values.
Nothing here calls the project's ray helpers (`Intrinsics.pixel_rays`, `camera_points`).
"""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.io.memory_sink import MemorySink

LOW, HIGH = np.array([0.1, -0.1, 0.0]), np.array([0.9, 0.3, 0.2])  # the box in its own (local) coordinates
K = np.array([[70.0, 0, 30.2], [0, 55.0, 26.7], [0, 0, 1]])
WIDTH, HEIGHT = 64, 48


def _box_object() -> hg.MeshObject:
    corners = np.array([[x, y, z] for x in (LOW[0], HIGH[0]) for y in (LOW[1], HIGH[1]) for z in (LOW[2], HIGH[2])])
    # corner index = 4 * ix + 2 * iy + iz; two triangles per face, outward winding
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],   # x = low, x = high
             [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],   # y = low, y = high
             [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]   # z = low, z = high
    return hg.MeshObject("bar", corners, faces, category_id=2,
                         local2world=hg.object_pose([0.3, -0.2, 0.5], [0.3, -0.2, 0.9], 1.3))


def _scene() -> hg.Scene:
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 30.0, name="floor", category_id=1))  # z = 0
    scene.add(_box_object())
    scene.camera.intrinsics = hg.Intrinsics(K, WIDTH, HEIGHT, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([2.0, -1.7, 1.9], [0.6, 0.1, 0.6]))
    scene.camera.add_keypoint(hg.look_at([-1.2, 1.9, 2.3], [0.6, 0.1, 0.5]))
    return scene


def _slab(origin: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Ray parameter of the first hit of origin + t * direction (rows) with the box [LOW, HIGH]; inf if missed."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (LOW - origin) / direction, (HIGH - origin) / direction
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    return np.where((near <= far) & (near > 0), near, np.inf)


def _oracle(scene: hg.Scene, cam2world: np.ndarray) -> dict[str, np.ndarray]:
    """Expected depth, distance, instance id and NOCS of every pixel centre."""
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(np.float64)
    camera_rays = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones_like(u)], -1).reshape(-1, 3)
    unit = camera_rays / np.linalg.norm(camera_rays, axis=1, keepdims=True)
    origin, world_dirs = cam2world[:3, 3], unit @ cam2world[:3, :3].T
    with np.errstate(divide="ignore"):
        t_floor = np.where(world_dirs[:, 2] < 0, -origin[2] / world_dirs[:, 2], np.inf)
    floor_hit = origin[:2] + np.where(np.isfinite(t_floor), t_floor, 0)[:, None] * world_dirs[:, :2]
    t_floor[np.abs(floor_hit).max(axis=1) > 15.0] = np.inf  # the floor is a 30 m square
    box = scene.objects[1]
    to_local = np.linalg.inv(box.local2world)
    local_origin = to_local[:3, :3] @ origin + to_local[:3, 3]
    local_dirs = world_dirs @ to_local[:3, :3].T  # not unit: t stays the world distance
    t_box = _slab(np.broadcast_to(local_origin, local_dirs.shape), local_dirs)
    distance = np.minimum(t_floor, t_box)
    ids = np.where(t_box < t_floor, 2, np.where(np.isfinite(t_floor), 1, 0))
    local_hit = local_origin + np.where(np.isfinite(t_box), t_box, 0)[:, None] * local_dirs
    nocs = np.where((ids == 2)[:, None], (local_hit - (LOW + HIGH) / 2) / np.linalg.norm(HIGH - LOW) + 0.5, 0.0)
    shape = (HEIGHT, WIDTH)
    return {"distance": distance.reshape(shape), "depth": (distance * unit[:, 2]).reshape(shape),
            "ids": ids.reshape(shape), "nocs": nocs.reshape(shape + (3,))}


def _away_from_silhouettes(ids: np.ndarray) -> np.ndarray:
    padded = np.pad(ids, 1, mode="edge")
    same = np.ones(ids.shape, bool)
    for dv in (-1, 0, 1):
        for du in (-1, 0, 1):
            same &= padded[1 + dv:1 + dv + ids.shape[0], 1 + du:1 + du + ids.shape[1]] == ids
    return same


def test_depth_distance_ids_and_nocs_equal_rays_written_from_u_v_and_K(gl_context):
    scene = _scene()
    sink = MemorySink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"], depth=True, distance=True, nocs=True))
    for pose, frame in zip(scene.camera.keypoints, sink.frames):
        expected = _oracle(scene, pose)
        inner = _away_from_silhouettes(expected["ids"])
        assert (expected["ids"][inner] == 2).sum() > 100 and (expected["ids"][inner] == 1).sum() > 500
        np.testing.assert_array_equal(frame["instance_segmaps"][inner], expected["ids"][inner])
        # ids may differ only on silhouette pixels, and only by a sliver there
        assert (frame["instance_segmaps"] != expected["ids"]).sum() <= (~inner).sum() // 4
        np.testing.assert_allclose(frame["depth"][inner], expected["depth"][inner], rtol=2e-6, atol=2e-6)
        np.testing.assert_allclose(frame["distance"][inner], expected["distance"][inner], rtol=2e-6, atol=2e-6)
        box = inner & (expected["ids"] == 2)
        np.testing.assert_allclose(frame["nocs"][box], expected["nocs"][box], atol=2e-5)
        # the NOCS cube is the box normalized by its own diagonal: asymmetric ranges per channel
        span = frame["nocs"][box].max(axis=0) - frame["nocs"][box].min(axis=0)
        assert span[0] > span[1] > span[2] > 0
        assert (frame["nocs"][frame["instance_segmaps"] == 0] == 0).all()


def test_specific_pixels_back_project_to_their_object_coordinates(gl_context):
    """Pixel by pixel, written out: NOCS at (u, v) is the box point the ray through (u, v) meets."""
    scene = _scene()
    pose = scene.camera.keypoints[0]
    frame = hg.RasterView(scene).render(pose, ["depth", "instance_segmaps"])
    sink = MemorySink()
    hg.render_labels(scene, [sink], hg.LabelRequest(map_by=["instance"], nocs=True))
    nocs = sink.frames[0]["nocs"]
    inner = _away_from_silhouettes(frame["instance_segmaps"]) & (frame["instance_segmaps"] == 2)
    rows, cols = np.nonzero(inner)
    picks = np.linspace(0, len(rows) - 1, 7).astype(int)
    to_local = np.linalg.inv(scene.objects[1].local2world)
    for v, u in zip(rows[picks], cols[picks]):
        z = float(frame["depth"][v, u])
        camera_point = np.array([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z, 1.0])
        local = (to_local @ pose @ camera_point)[:3]
        assert np.all(local >= LOW - 1e-5) and np.all(local <= HIGH + 1e-5)  # on the box
        expected = (local - (LOW + HIGH) / 2) / np.sqrt(0.8 ** 2 + 0.4 ** 2 + 0.2 ** 2) + 0.5
        np.testing.assert_allclose(nocs[v, u], expected, atol=2e-5)
