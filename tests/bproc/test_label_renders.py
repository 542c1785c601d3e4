"""bproc.renderer's extra renders against analytic truth: optical flow of a floor under a known camera motion
(BlenderProc's signs: forward to the next frame, y down unless blender_image_coordinate_style), NOCS of a rotated
cube (0.5 p + 0.5 of the local point, alpha 1 on the object), stereo pairs (the right eye's disparity fx b / z),
and set_output_format's colors (JPEG round trip, 16-bit, view transforms, a transparent film's alpha)."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture


def _down(x: float, y: float, z: float) -> np.ndarray:
    pose = np.eye(4)  # Blender camera axes: looking along world -Z, image up = world +Y
    pose[:3, 3] = [x, y, z]
    return pose


def test_optical_flow_of_a_floor_under_a_known_camera_motion(gl_context, bproc) -> None:  # noqa: F811
    bproc.object.create_primitive("PLANE", size=100)
    bproc.camera.add_camera_pose(_down(0, 0, 3))
    bproc.camera.add_camera_pose(_down(0.2, 0.1, 3))
    fx = bproc.camera.get_intrinsics_as_K_matrix()[0, 0]
    du, dv = -fx * 0.2 / 3, fx * 0.1 / 3  # the camera moves right and image-up: the floor moves left and down
    data = bproc.renderer.render_optical_flow()
    forward, backward = data["forward_flow"], data["backward_flow"]
    assert len(forward) == 2 and forward[0].dtype == np.float32 and forward[0].shape == (24, 32, 2)
    assert np.allclose(forward[0][..., 0], du, atol=1e-3) and np.allclose(forward[0][..., 1], dv, atol=1e-3)
    assert np.allclose(backward[1][..., 0], -du, atol=1e-3) and np.allclose(backward[1][..., 1], -dv, atol=1e-3)
    assert not forward[1].any() and not backward[0].any()  # no next / previous frame: the pose is held
    blender = bproc.renderer.render_optical_flow(get_backward_flow=False, blender_image_coordinate_style=True)
    assert set(blender) == {"forward_flow"}
    assert np.allclose(blender["forward_flow"][0][..., 1], -dv, atol=1e-3)


def test_nocs_of_a_rotated_cube(gl_context, bproc) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE", location=[0.3, -0.2, 0.0], rotation=[0, 0, 0.5])  # +-1 m
    bproc.camera.add_camera_pose(_down(0.3, -0.2, 5.0))
    nocs = bproc.renderer.render_nocs()["nocs"]
    assert len(nocs) == 1 and nocs[0].dtype == np.float32 and nocs[0].shape == (24, 32, 4)
    image = nocs[0]
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    world = np.stack([0.3 + (u - K[0, 2]) / K[0, 0] * 4.0, -0.2 - (v - K[1, 2]) / K[1, 1] * 4.0,
                      np.ones(u.shape)], axis=-1)  # the top face (z = 1) is 4 m below the camera
    c, s = np.cos(0.5), np.sin(0.5)
    to_local = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    local = (world - np.array([0.3, -0.2, 0.0])) @ to_local.T
    on_top = np.all(np.abs(local[..., :2]) < 0.98, axis=-1)
    off = np.any(np.abs(local[..., :2]) > 1.02, axis=-1)
    assert on_top.sum() > 100 and off.sum() > 10
    assert np.allclose(image[on_top, :3], 0.5 * local[on_top] + 0.5, atol=2e-3)  # float16 precision
    assert np.all(image[on_top, 3] == 1.0)
    assert not image[off].any()  # transparent black background
    assert cube.get_location()[2] == 0.0


def test_stereo_pairs_have_blenders_parallel_disparity(gl_context, bproc) -> None:  # noqa: F811
    bproc.object.create_primitive("CUBE", size=0.5)
    bproc.camera.add_camera_pose(_down(0, 0, 4.0))
    bproc.camera.set_stereo_parameters("PARALLEL", 0.0, 0.5)
    bproc.renderer.toggle_stereo(True)
    bproc.renderer.enable_depth_output(activate_antialiasing=False)
    bproc.renderer.enable_segmentation_output(map_by=["instance", "name"])
    data = bproc.renderer.render(output_key=None)
    depth, instances = data["depth"][0], data["instance_segmaps"][0]
    assert depth.shape == (2, 24, 32) and instances.shape == (2, 24, 32)
    fx = bproc.camera.get_intrinsics_as_K_matrix()[0, 0]
    columns = [np.nonzero(instances[eye] == 1)[1].mean() for eye in (0, 1)]
    assert columns[0] - columns[1] == pytest.approx(fx * 0.5 / 3.75, abs=0.5)  # the right eye sees it further left
    assert np.allclose(depth[1][instances[1] == 1], 3.75, atol=1e-4)
    assert [m["idx"] for m in data["instance_attribute_maps"][0]] == [0, 1]  # one list over both eyes
    bproc.camera.set_stereo_parameters("OFFAXIS", 2.0, 0.5)
    with pytest.raises(Exception, match="OFFAXIS"):
        bproc.renderer.render(output_key=None)


def test_output_formats_of_colors(bproc) -> None:  # noqa: F811
    from hybridgen.bproc.frame_outputs import _colors as encoded
    from hybridgen.render.view_transform import STANDARD
    from hybridgen.render.tonemap import to_srgb8, to_srgb16

    def _colors(values: dict) -> np.ndarray:
        return encoded(values, STANDARD)

    import io

    from PIL import Image

    v, u = np.mgrid[0:24, 0:32]
    linear = np.stack([u / 31, v / 23, (u + v) / 54], axis=-1).astype(np.float32)  # smooth ramps
    values = {"colors": to_srgb8(linear), "colors_hdr": linear.astype(np.float16)}
    assert np.array_equal(_colors(values), values["colors"])
    bproc.renderer.set_output_format(file_format="JPEG", jpg_quality=50)
    jpeg = _colors(values)
    assert jpeg.dtype == np.uint8 and jpeg.shape == (24, 32, 3) and not np.array_equal(jpeg, values["colors"])
    assert np.abs(jpeg.astype(int) - values["colors"]).mean() < 8
    buffer = io.BytesIO()  # what libjpeg gives at quality 50 (chroma subsampled below 90, as Blender)
    Image.fromarray(values["colors"]).save(buffer, format="JPEG", quality=50, subsampling=2)
    assert np.array_equal(jpeg, np.asarray(Image.open(buffer).convert("RGB")))
    with pytest.raises(Exception, match="color_depth"):
        bproc.renderer.set_output_format(color_depth=16)  # JPEG is 8-bit
    bproc.renderer.set_output_format(file_format="PNG", color_depth=16)
    sixteen = _colors(values)
    assert sixteen.dtype == np.uint16
    assert np.array_equal(sixteen, to_srgb16(linear.astype(np.float16).astype(np.float32)))
    bproc.renderer.set_output_format(view_transform="Filmic")  # tests/render/test_filmic_view.py
    with pytest.raises(Exception, match="not supported"):
        bproc.renderer.set_output_format(view_transform="False Color")


def test_transparent_film_gives_alpha_where_surfaces_are(bproc) -> None:  # noqa: F811
    bproc.object.create_primitive("PLANE", size=2)  # x, y in -1..1 at z = 0
    bproc.camera.add_camera_pose(_down(0.3, 0.0, 4.0))
    bproc.renderer.set_max_amount_of_samples(2)
    bproc.renderer.set_output_format(enable_transparency=True)
    rgba = bproc.renderer.render()["colors"][0]
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    x, y = 0.3 + (u - K[0, 2]) / K[0, 0] * 4.0, -(v - K[1, 2]) / K[1, 1] * 4.0  # pixel centres on z = 0
    covered = (np.abs(x) < 1) & (np.abs(y) < 1)
    assert rgba.shape == (24, 32, 4) and rgba.dtype == np.uint8 and 0 < covered.sum() < covered.size
    assert np.array_equal(rgba[..., 3], np.where(covered, 255, 0))
    assert not rgba[~covered].any() and rgba[covered][:, :3].any()
    # BlenderProc loads the alpha of the keys asked for only; a JPEG film has none
    bproc.renderer.set_max_amount_of_samples(1)  # one sample with the default noise threshold renders, as in Cycles
    assert bproc.renderer.render(keys_with_alpha_channel=set())["colors"][0].shape == (24, 32, 3)
    bproc.renderer.set_output_format(file_format="JPEG")
    assert bproc.renderer.render()["colors"][0].shape == (24, 32, 3)
