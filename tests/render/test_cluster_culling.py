"""Cluster culling (hybridgen/render/raster/triangle_clusters.py) leaves out only triangles that make no fragment: every
label of a view that culls is bit-identical to one that draws everything - dense closed meshes (back-facing
clusters), a mirrored placement, an open dense grid partly outside the image, the camera inside a closed mesh's
box (no back-face culling there) - and the test checks that clusters were really left out."""
from __future__ import annotations

import numpy as np
import trimesh

import hybridgen as hg
from hybridgen.render.raster.label_targets import packed_targets
from hybridgen.render.raster.triangle_clusters import (CLUSTER_TRIANGLES, MIN_TRIANGLES, build_clusters, draw_commands,
                                                visible_clusters)


def _grid(n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """An open n x n quad grid over [-4, 4]^2 at z = 0 (2 n^2 triangles), rows in order."""
    xs = np.linspace(-4, 4, n + 1)
    gx, gy = np.meshgrid(xs, xs)
    vertices = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    a, b, c, d = i, i + 1, i + n + 2, i + n + 1
    faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    order = np.argsort(np.concatenate([i.ravel(), i.ravel()]), kind="stable")  # spatially coherent order
    return vertices, faces[order]


def _scene() -> hg.Scene:
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=0.8)  # 20,480 triangles: 40 clusters
    scene = hg.Scene()
    vertices, faces = _grid()
    scene.add(hg.MeshObject("grid", vertices, faces, category_id=1))
    scene.add(hg.MeshObject("smooth", sphere.vertices, sphere.faces, vertex_normals=sphere.vertices / 0.8,
                            category_id=2, local2world=hg.object_pose([0.5, 0.3, 0.9])))
    mirrored = hg.object_pose([-1.6, 0.8, 0.9])
    mirrored[:3, 0] *= -1  # negative scale along x: winding flips
    scene.add(hg.MeshObject("flat_mirrored", sphere.vertices, sphere.faces, category_id=3, local2world=mirrored))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, 96, 72)
    for loc, at in (([3, -3, 2], [0, 0, 0.4]), ([-2.5, 1, 1.2], [0.5, 0.3, 0.9]), ([0.6, 2.5, 0.9], [0.5, 0.3, 0.9]),
                    ([0.5, 0.3, 1.5], [0.5, 0.3, 0.0]),  # inside the smooth sphere's box, near plane inside it
                    ([0, 0, 6.0], [0.2, 0.1, 0.0])):
        scene.camera.add_keypoint(hg.look_at(loc, at))
    return scene


def test_culled_labels_equal_unculled_ones(gl_context):
    scene = _scene()
    culled, full = hg.RasterView(scene), hg.RasterView(scene, cull_clusters=False)
    assert all(gpu.clusters is not None for gpu in culled.gpu_objects)
    assert all(gpu.clusters is None for gpu in full.gpu_objects)
    request = hg.LabelRequest(map_by=["class", "instance"])
    targets = packed_targets(request, request.tables(culled), scene, {"normals": "octahedral_uint16"})
    left_out = back_faces = 0
    intr = scene.camera.intrinsics
    for pose in scene.camera.keypoints:
        a, b = culled.render_raw(pose), full.render_raw(pose)
        assert a.instance.any()
        np.testing.assert_array_equal(a.normal_depth.view(np.uint32), b.normal_depth.view(np.uint32))
        np.testing.assert_array_equal(a.instance, b.instance)
        pa, pb = culled.render_raw(pose, targets=targets), full.render_raw(pose, targets=targets)
        for name in ("depth_image", "normal_codes", "instance", "category"):
            np.testing.assert_array_equal(getattr(pa, name), getattr(pb, name))
        world2cam = np.linalg.inv(pose)
        for gpu, obj in zip(culled.gpu_objects, scene.objects):
            modelview = world2cam @ obj.local2world
            camera_local = (np.linalg.inv(obj.local2world) @ pose)[:3, 3]
            frustum = visible_clusters(gpu.clusters, modelview, intr.K, intr.width, intr.height, intr.clip_start,
                                       intr.clip_end, None)
            both = visible_clusters(gpu.clusters, modelview, intr.K, intr.width, intr.height, intr.clip_start,
                                    intr.clip_end, camera_local)
            left_out += int((~frustum).sum())
            back_faces += int((frustum & ~both).sum()) if obj.is_closed else 0
    assert left_out > 0 and back_faces > 0  # both tests really left clusters out


def test_clusters_keep_the_triangle_order():
    vertices, faces = _grid(40)  # 3200 triangles
    clusters = build_clusters(vertices, faces)
    assert len(faces) >= MIN_TRIANGLES and clusters.size == -(-len(faces) // CLUSTER_TRIANGLES)
    assert clusters.first[0] == 0 and (clusters.first[1:] == clusters.first[:-1] + clusters.count[:-1]).all()
    assert clusters.count.sum() == len(faces)
    for k in range(clusters.size):  # every vertex of a cluster lies in its box
        tri = vertices[faces[clusters.first[k]:clusters.first[k] + clusters.count[k]]].reshape(-1, 3)
        assert (tri >= clusters.corners[k].min(axis=0)).all() and (tri <= clusters.corners[k].max(axis=0)).all()
    keep = np.zeros(clusters.size, bool)
    keep[[0, 1, 3, clusters.size - 1]] = True
    commands = draw_commands(clusters, keep)
    last = clusters.first[-1] + clusters.count[-1]
    np.testing.assert_array_equal(commands, [
        [3 * 2 * CLUSTER_TRIANGLES, 1, 0, 0, 0],
        [3 * CLUSTER_TRIANGLES, 1, 3 * 3 * CLUSTER_TRIANGLES, 0, 3 * CLUSTER_TRIANGLES],
        [3 * (last - clusters.first[-1]), 1, 3 * clusters.first[-1], 0, clusters.first[-1]]])
    assert draw_commands(clusters, np.zeros(clusters.size, bool)).shape == (0, 5)
    assert build_clusters(vertices, faces[:MIN_TRIANGLES - 1]) is None  # small meshes are drawn whole
