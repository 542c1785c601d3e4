"""Values the mutation run (tools/mutation) found unchecked in render/: the near-plane reach used for culling,
stereo layouts and baseline validation as written to HDF5, object_records through the HDF5 writer, albedo of
an in-memory RGB texture, the albedo pass at a second image size."""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

import hybridgen as hg
from hybridgen.errors import InputError
from hybridgen.render.raster.projection import near_plane_corner_distance


@pytest.mark.parametrize("cx, cy", [(10.0, 25.0), (55.0, 3.0)])
def test_near_plane_corner_distance_is_the_farthest_image_corner(cx, cy):
    """Image corners are pixel edges: u in {-0.5, W - 0.5}, v in {-0.5, H - 0.5}; the near-plane point under
    (u, v) is near * ((u - cx) / fx, (v - cy) / fy, 1). Principal points far off-centre both ways, so each
    of the four edges is the farthest once."""
    K = np.array([[50.0, 0, cx], [0, 40.0, cy], [0, 0, 1]])
    width, height, near = 64, 32, 0.2
    corners = [np.array([(u - cx) / 50.0, (v - cy) / 40.0, 1.0]) * near
               for u in (-0.5, width - 0.5) for v in (-0.5, height - 0.5)]
    expected = max(np.linalg.norm(c) for c in corners)
    assert near_plane_corner_distance(K, width, height, near) == pytest.approx(expected, rel=1e-12)


def test_an_object_cut_by_the_near_plane_shows_its_inside(gl_context):
    """Back-face culling is an optimisation that must never show: a flat closed box (scaled 0.2 in z) whose
    top face lies between the camera and the near plane shows, everywhere, its bottom face from inside at
    camera z = 0.05 + 0.2 m - as a ray cast started at the near plane sees it."""
    scene = hg.Scene()
    scene.add(hg.make_primitive("cube", 1.0, name="slab", category_id=1,
                                local2world=hg.object_pose([0, 0, -0.1], [0, 0, 0], [4.0, 4.0, 0.2])))
    scene.camera.intrinsics = hg.Intrinsics(np.array([[20.0, 0, 7.5], [0, 20.0, 5.5], [0, 0, 1]]), 16, 12,
                                            clip_start=0.1)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0.05], [0, 0, 0, 1]]))
    depth = hg.RasterView(scene).render(scene.camera.keypoints[0], ["depth"])["depth"]
    np.testing.assert_allclose(depth, 0.25, rtol=1e-5)


def _small_scene() -> hg.Scene:
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 6.0, name="floor", category_id=1))
    scene.add(hg.make_primitive("cube", 0.6, name="box", category_id=2, local2world=hg.object_pose([0, 0, 0.3])))
    scene.add(hg.make_primitive("sphere", 0.4, name="far", category_id=3, local2world=hg.object_pose([0, 0, 40])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.add_keypoint(hg.look_at([2.0, -2.0, 1.5], [0, 0, 0.3]))
    scene.camera.add_keypoint(hg.look_at([-2.0, -1.5, 1.2], [0, 0, 0.3]))
    return scene


def test_stereo_files_have_a_leading_eye_axis_and_a_positive_baseline(gl_context, tmp_path):
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings
    from hybridgen.render.render_color import render_color

    scene = _small_scene()
    for bad in (0.0, -0.1):
        with pytest.raises(InputError, match="baseline"):
            render_color(scene, [], PathTraceSettings(samples=1, max_bounces=0), stereo_baseline=bad,
                         variant=choose_variant())
    writer = hg.Hdf5SingleFileWriter(tmp_path / "stereo.hdf5")
    render_color(scene, [writer], PathTraceSettings(samples=1, max_bounces=0), labels=hg.LabelRequest(map_by=["instance"]),
                 stereo_baseline=0.2, variant=choose_variant())
    writer.finalize()
    with h5py.File(tmp_path / "stereo.hdf5") as f:
        assert f["colors"].shape == (2, 2, 16, 24, 3) and f["depth"].shape == (2, 2, 16, 24)
        assert f["instance_segmaps"].shape == (2, 2, 16, 24)
        left, right = f["depth"][0]
        assert not np.array_equal(left, right)


def test_object_records_reach_the_hdf5_file(gl_context, tmp_path):
    scene = _small_scene()
    writer = hg.Hdf5SingleFileWriter(tmp_path / "records.hdf5")
    hg.render_labels(scene, [writer], hg.LabelRequest(map_by=["instance"], object_records=True))
    writer.finalize()
    with h5py.File(tmp_path / "records.hdf5") as f:
        records = [json.loads(r) for r in f["object_records"][()]]
        instance = f["instance_segmaps"][()]
    assert len(records) == 2
    for frame, entries in zip(instance, records):
        assert {r["name"] for r in entries} == {"floor", "box"}  # 'far' is above the view: no record
        for r in entries:
            assert r["px_count_visib"] == (frame == r["idx"]).sum() > 0


def test_albedo_of_an_in_memory_rgb_texture(gl_context):
    """An (H, W, 3) uint8 texture array is sampled like the same texture with alpha: four colored quadrants on
    a quad filling the view, each quarter of the image showing its quadrant's linear (sRGB-decoded) color."""
    from hybridgen.render.raster.albedo_pass import AlbedoPass

    colors = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8)
    texels = np.repeat(np.repeat(colors, 4, axis=0), 4, axis=1)  # 8 x 8: quadrants constant under bilinear
    quad = hg.MeshObject("quad", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]],
                         category_id=1)
    quad.uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    quad.material.base_color_texture = texels
    scene = hg.Scene()
    scene.add(quad)
    scene.camera.intrinsics = hg.Intrinsics(np.array([[40.0, 0, 15.5], [0, 40.0, 15.5], [0, 0, 1]]), 32, 32)
    scene.camera.add_keypoint(np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 2.0], [0, 0, 0, 1]]))
    view = hg.RasterView(scene)
    albedo = AlbedoPass(view).render(scene.camera.keypoints[0])
    # image right = world +x = u, image up = world +y = v (file v up): top-left quarter is texel row 0 ... as
    # stored top-down, so the top half of the image shows texel row 0, the left half texel column 0
    quarters = {(0, 0): albedo[2:8, 2:8], (0, 1): albedo[2:8, 24:30], (1, 0): albedo[24:30, 2:8],
                (1, 1): albedo[24:30, 24:30]}
    for (row, column), patch in quarters.items():
        expected = colors[row, column] / 255.0  # 0 or 1: the same in sRGB and linear
        np.testing.assert_allclose(patch.reshape(-1, 3), np.broadcast_to(expected, (36, 3)), atol=1e-3)


def test_albedo_pass_follows_a_change_of_image_size(gl_context):
    from hybridgen.render.raster.albedo_pass import AlbedoPass

    scene = _small_scene()
    view = hg.RasterView(scene)
    albedo = AlbedoPass(view)
    pose = scene.camera.keypoints[0]
    full_size = scene.camera.intrinsics
    large = albedo.render(pose)
    scene.camera.intrinsics = full_size.resized(12, 8)
    small = albedo.render(pose)
    scene.camera.intrinsics = full_size.resized(48, 32)
    larger = albedo.render(pose)
    assert large.shape == (16, 24, 3) and small.shape == (8, 12, 3) and larger.shape == (32, 48, 3)
    for image in (small, larger):
        scene.camera.intrinsics = full_size.resized(image.shape[1], image.shape[0])
        np.testing.assert_array_equal(image, AlbedoPass(hg.RasterView(scene)).render(pose))
