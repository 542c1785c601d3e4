"""scene/ values the mutation run (tools/mutation) found unchecked: resizing an off-centre K, keypoint indices,
the largest allowed image, an inside-out closed mesh (back-face culling must not hide it)."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg


def test_resized_off_centre_K_maps_pixel_edges():
    """u' + 0.5 = (u + 0.5) * W' / W, worked out: cx 40.3 -> (40.8 * 0.5) - 0.5 = 19.9, cy 12.7 -> 6.1."""
    intr = hg.Intrinsics(np.array([[100.0, 0, 40.3], [0, 80.0, 12.7], [0, 0, 1]]), 96, 72)
    half = intr.resized(48, 36)
    np.testing.assert_allclose(half.K, [[50.0, 0, 19.9], [0, 40.0, 6.1], [0, 0, 1]], atol=1e-12)
    assert (half.width, half.height) == (48, 36)
    wide = intr.resized(width=192)  # the height follows the aspect ratio
    assert (wide.width, wide.height) == (192, 144)
    np.testing.assert_allclose(wide.K[:2, 2], [(40.3 + 0.5) * 2 - 0.5, (12.7 + 0.5) * 2 - 0.5], atol=1e-12)


def test_keypoint_indices_count_from_zero():
    camera = hg.Scene().camera
    assert [camera.add_keypoint(hg.look_at([i + 1.0, 0, 1], [0, 0, 0])) for i in range(3)] == [0, 1, 2]


def test_largest_allowed_image_is_16384_squared():
    K = np.array([[1000.0, 0, 8191.5], [0, 1000.0, 8191.5], [0, 0, 1]])
    assert hg.Intrinsics(K, 16384, 16384).resolution == (16384, 16384)
    for width, height in ((16385, 16384), (16384, 16385)):
        with pytest.raises((hg.InputError, ValueError)):
            hg.Intrinsics(K, width, height)


def test_inside_out_closed_mesh_is_drawn_from_outside(gl_context):
    """A closed cube with every face wound inwards (volume -0.216 m^3) is still seen from outside: the label
    pass may cull back faces only of meshes that are closed AND outward-wound."""
    normal = hg.make_primitive("cube", 0.6, name="cube", category_id=1, local2world=hg.object_pose([0, 0, 0.5]))
    inverted = hg.MeshObject("inverted", normal.vertices, np.asarray(normal.faces)[:, ::-1], category_id=1,
                             local2world=normal.local2world.copy())
    depths = []
    for obj in (normal, inverted):
        scene = hg.Scene()
        scene.add(obj)
        scene.camera.intrinsics = hg.Intrinsics.from_fov(0.8, 32, 24)
        scene.camera.add_keypoint(hg.look_at([3.0, -2.5, 2.0], [0, 0, 0.5]))
        out = hg.RasterView(scene).render(scene.camera.keypoints[0], ["depth", "instance_segmaps"])
        assert (out["instance_segmaps"] == 1).sum() > 50
        depths.append(out["depth"])
    np.testing.assert_allclose(depths[1], depths[0], rtol=1e-6)


def test_rotation_about_a_non_unit_axis():
    from hybridgen.scene.frames import rotation_about_axis

    quarter = rotation_about_axis(np.array([0.0, 0.0, 2.5]), np.pi / 2)  # any length: only the direction counts
    np.testing.assert_allclose(quarter, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    tilted = rotation_about_axis(np.array([3.0, 0.0, 0.0]), 0.3)
    np.testing.assert_allclose(tilted @ [0, 1, 0], [0, np.cos(0.3), np.sin(0.3)], atol=1e-12)
