"""Labels against analytic ground truth: planes, spheres, known id layouts, pixel-centre sampling."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.render.raster.gl_context import shared_context
from hybridgen.render.raster.raster_view import software_renderer
from hybridgen.scene.primitives import make_primitive
from tests.conftest import camera_at

W, H = 64, 48


def _quad(name: str, x0: float, x1: float, y0: float, y1: float, z: float, instance_cat: int) -> hg.MeshObject:
    """An axis-aligned rectangle in the plane z (world), facing +Z."""
    vertices = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
    return hg.MeshObject(name, vertices, [[0, 1, 2], [0, 2, 3]], category_id=instance_cat)


def _down_camera(intr: hg.Intrinsics, height: float) -> hg.Scene:
    """Camera at (0, 0, height) looking down -Z with OpenCV x = world +X, y = world -Y."""
    scene = hg.Scene()
    scene.camera.intrinsics = intr
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])
    pose[2, 3] = height
    scene.camera.add_keypoint(pose)
    return scene


@pytest.mark.parametrize("d", [0.5, 3.0, 40.0])
def test_plane_depth_and_distance(gl_context, d):
    intr = hg.Intrinsics.from_fov(1.2, W, H)
    scene = _down_camera(intr, d)
    scene.add(_quad("plane", -1e3, 1e3, -1e3, 1e3, 0.0, 1))
    out = hg.RasterView(scene).render(scene.camera.keypoints[0], ["depth", "distance", "normals"])
    assert np.max(np.abs(out["depth"] / d - 1)) < 1e-6
    cos_angle = 1.0 / np.linalg.norm(intr.pixel_rays(), axis=-1)
    assert np.max(np.abs(out["distance"] * cos_angle / d - 1)) < 1e-6
    # camera looks down: the plane's +Z normal points at the camera, i.e. -z in camera axes
    np.testing.assert_allclose(out["normals"].reshape(-1, 3), np.tile([0, 0, -1.0], (W * H, 1)), atol=1e-6)


def test_plane_seen_from_behind_flips_normal_and_world_space(gl_context):
    intr = hg.Intrinsics.from_fov(1.0, W, H)
    scene = hg.Scene()
    scene.camera.intrinsics = intr
    scene.camera.add_keypoint(hg.look_at([0, 0, -2], [0, 0, 0]))
    scene.add(_quad("plane", -1e3, 1e3, -1e3, 1e3, 0.0, 1))  # faces +Z, camera is below it
    out = hg.RasterView(scene, normals_space="world").render(scene.camera.keypoints[0], ["normals", "depth"])
    np.testing.assert_allclose(out["normals"].reshape(-1, 3), np.tile([0, 0, -1.0], (W * H, 1)), atol=1e-6)
    assert np.max(np.abs(out["depth"] - 2.0)) < 2e-6


def test_sphere_normals_match_analytic(gl_context):
    intr = hg.Intrinsics.from_fov(0.5, 96, 96)
    center = np.array([0.2, -0.1, 0.3])
    radius = 0.7
    pose_obj = np.eye(4)
    pose_obj[:3, 3] = center
    scene = camera_at([3.0, -2.0, 1.5], center, intr)
    ball = trimesh.creation.icosphere(subdivisions=6, radius=radius)  # 82k faces: facets below 0.05 deg
    scene.add(hg.MeshObject("ball", ball.vertices, ball.faces, vertex_normals=ball.vertices / radius,
                            category_id=1, local2world=pose_obj))
    pose = scene.camera.keypoints[0]
    out = hg.RasterView(scene, normals_space="world").render(pose, ["normals", "instance_segmaps", "depth"])
    # Analytic ray-sphere intersection through each pixel centre.
    rays = intr.pixel_rays().reshape(-1, 3)
    dirs = rays / np.linalg.norm(rays, axis=1, keepdims=True) @ pose[:3, :3].T
    origin = pose[:3, 3]
    oc = origin - center
    b = dirs @ oc
    disc = b ** 2 - (oc @ oc - radius ** 2)
    hit = disc > 0
    t = -b - np.sqrt(np.where(hit, disc, 0))
    points = origin + t[:, None] * dirs
    expected = (points - center) / radius
    # Away from the silhouette: the ray meets the surface at less than 70 degrees from its normal.
    grazing = np.einsum("ij,ij->i", -dirs, expected)
    interior = hit & (grazing > np.cos(np.radians(70)))
    assert interior.sum() > 2000
    got = out["normals"].reshape(-1, 3)[interior]
    cosine = np.clip(np.einsum("ij,ij->i", got, expected[interior]), -1, 1)
    angle = np.degrees(np.arccos(cosine))
    assert angle.max() < 0.1, angle.max()
    assert (out["instance_segmaps"].reshape(-1)[interior] == 1).all()
    # Against the rendered surface point itself: interpolated sphere normals are exactly (p - c) / |p - c|.
    depth = out["depth"].reshape(-1)[interior]
    p = origin + (rays[interior] * depth[:, None]) @ pose[:3, :3].T
    radial = (p - center) / np.linalg.norm(p - center, axis=1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", got, radial), -1, 1)))
    # (what remains is the rasterizer's sub-pixel vertex snapping, measured 0.006 deg median)
    assert np.median(angle) < 0.02 and angle.max() < 0.05, np.percentile(angle, [50, 100])


def test_id_layout_per_pixel_with_edges_off_centre(gl_context):
    """Rectangles parallel to the image plane; every edge a quarter pixel from the nearest pixel centres."""
    intr = hg.Intrinsics(np.array([[50.0, 0, 31.5], [0, 50.0, 23.5], [0, 0, 1]]), W, H)
    cam_height = 10.0
    scene = _down_camera(intr, cam_height)
    # (u0, u1, v0, v1) image extents in pixel coordinates at the rectangle's depth, then world coordinates
    layout = [((3.25, 20.75, 5.25, 30.75), 0.0, 7), ((15.25, 40.75, 20.25, 44.75), 2.0, 8),
              ((35.25, 60.25, 2.75, 15.25), 5.0, 9)]
    for i, ((u0, u1, v0, v1), z, cat) in enumerate(layout):
        depth = cam_height - z
        x0, x1 = (u0 - 31.5) * depth / 50.0, (u1 - 31.5) * depth / 50.0
        y0, y1 = -(v1 - 23.5) * depth / 50.0, -(v0 - 23.5) * depth / 50.0  # image v down = world -Y
        scene.add(_quad(f"r{i}", x0, x1, y0, y1, z, cat))
    out = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps", "depth"])
    u, v = np.meshgrid(np.arange(W), np.arange(H))
    expected = np.zeros((H, W), np.int32)
    expected_depth = np.full((H, W), np.inf)
    for i, ((u0, u1, v0, v1), z, _) in enumerate(layout):
        inside = (u > u0) & (u < u1) & (v > v0) & (v < v1) & (cam_height - z < expected_depth)
        expected[inside] = i + 1
        expected_depth[inside] = cam_height - z
    np.testing.assert_array_equal(out["instance_segmaps"], expected)
    np.testing.assert_allclose(out["depth"], expected_depth, rtol=1e-6)
    request = hg.LabelRequest(map_by=["class", "instance"])
    view = hg.RasterView(scene)
    values = request.compute(view.render_raw(scene.camera.keypoints[0]), request.tables(view))
    np.testing.assert_array_equal(values["category_id_segmaps"], np.array([0, 7, 8, 9])[expected])
    assert [r["idx"] for r in values["instance_attribute_maps"]] == [1, 2, 3]


def test_half_pixel_shift_is_detected(gl_context):
    """A rectangle from u = 10.25 to 20.75 must cover exactly columns 11..20 (u centres are integers).

    With labels half a pixel off (samples at u + 0.5 or u - 0.5) column 10 or 21 would change."""
    intr = hg.Intrinsics(np.array([[40.0, 0, 31.5], [0, 40.0, 23.5], [0, 0, 1]]), W, H)
    scene = _down_camera(intr, 4.0)
    x = lambda u: (u - 31.5) * 4.0 / 40.0  # noqa: E731
    y = lambda v: -(v - 23.5) * 4.0 / 40.0  # noqa: E731
    scene.add(_quad("r", x(10.25), x(20.75), y(30.75), y(8.25), 0.0, 1))
    ids = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"]
    cols = np.flatnonzero(ids.any(axis=0))
    rows = np.flatnonzero(ids.any(axis=1))
    assert (cols.min(), cols.max()) == (11, 20)
    assert (rows.min(), rows.max()) == (9, 30)


def test_off_centre_principal_point_and_anisotropic_focal(gl_context):
    intr = hg.Intrinsics(np.array([[70.0, 0, 20.3], [0, 45.0, 30.8], [0, 0, 1]]), W, H)
    scene = _down_camera(intr, 5.0)
    x = lambda u: (u - 20.3) * 5.0 / 70.0  # noqa: E731
    y = lambda v: -(v - 30.8) * 5.0 / 45.0  # noqa: E731
    scene.add(_quad("r", x(5.25), x(50.75), y(40.75), y(12.25), 0.0, 1))
    ids = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"]
    u, v = np.meshgrid(np.arange(W), np.arange(H))
    np.testing.assert_array_equal(ids, ((u > 5.25) & (u < 50.75) & (v > 12.25) & (v < 40.75)).astype(np.int32))


def test_camera_inside_closed_box_sees_its_walls(gl_context):
    """Back-face culling must not drop a closed mesh seen from inside (a room)."""
    intr = hg.Intrinsics.from_fov(1.2, W, H)
    scene = camera_at([0.3, -0.2, 0.1], [2, 1, 0.5], intr)
    room = make_primitive("cube", 6.0, name="room", category_id=1)
    assert room.is_closed
    scene.add(room)
    out = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps", "depth"])
    assert (out["instance_segmaps"] == 1).all()
    assert np.isfinite(out["depth"]).all() and out["depth"].max() < 6 * np.sqrt(3)


def test_near_plane_cutting_a_closed_mesh_shows_its_inside(gl_context):
    """Camera outside the box but its near plane inside it: rays start at the near plane and see back faces."""
    intr = hg.Intrinsics.from_fov(0.8, W, H, clip_start=0.5)
    scene = camera_at([0.0, -0.6, 0.0], [0, 1, 0], intr)  # box spans y in [-0.5, 0.5]
    scene.add(make_primitive("cube", 1.0, name="box", category_id=1))
    out = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps", "depth"])
    centre_depth = out["depth"][H // 2, W // 2]
    assert out["instance_segmaps"][H // 2, W // 2] == 1
    assert centre_depth == pytest.approx(1.1, abs=1e-5)  # the far wall at y = 0.5


def test_mirrored_object_transform_keeps_labels(gl_context):
    intr = hg.Intrinsics.from_fov(0.8, W, H)
    pose = np.diag([-1.0, 1.0, 1.0, 1.0])  # mirror in x: winding flips
    plain = camera_at([3, -2, 2], [0, 0, 0], intr)
    plain.add(make_primitive("cube", 1.0, name="a", category_id=1))
    mirrored = camera_at([3, -2, 2], [0, 0, 0], intr)
    mirrored.add(make_primitive("cube", 1.0, name="a", category_id=1, local2world=pose))
    a = hg.RasterView(plain).render(plain.camera.keypoints[0], ["depth", "normals"])
    b = hg.RasterView(mirrored).render(mirrored.camera.keypoints[0], ["depth", "normals"])
    np.testing.assert_allclose(a["depth"], b["depth"], rtol=1e-6)
    np.testing.assert_allclose(a["normals"], b["normals"], atol=1e-6)


def test_egl_device_choice(monkeypatch):
    from hybridgen.render.raster.gl_context import egl_device_for_cuda, egl_device_index

    monkeypatch.setenv("HYBRIDGEN_EGL_DEVICE", "3")
    assert egl_device_index() == 3 and egl_device_index(1) == 1
    monkeypatch.delenv("HYBRIDGEN_EGL_DEVICE")
    monkeypatch.setenv("CUDA_VISIBLE_DEVICES", "0")
    matched = egl_device_for_cuda(0)  # the EGL device of CUDA device 0 (NVIDIA's EGL), None without one
    if software_renderer(shared_context()):
        assert matched is None  # llvmpipe has no CUDA device: falls back to EGL device 0
    assert egl_device_index() == (0 if matched is None else matched)


def test_context_asks_for_the_gl_version_it_needs(monkeypatch):
    """The EGL context is asked for OpenGL 4.3: NVIDIA's EGL gives exactly the version asked for (3.3, moderngl's
    default, on an H100 with driver 580), where Mesa gives its highest; an older context is refused by name."""
    import moderngl

    from hybridgen.render.raster.gl_context import MIN_GL_VERSION, create_context

    asked: list[dict[str, object]] = []

    class OldContext:
        version_code = 330

        def release(self) -> None:
            pass

    def standalone(**kwargs: object) -> object:
        asked.append(kwargs)
        return OldContext()

    monkeypatch.setattr(moderngl, "create_standalone_context", standalone)
    with pytest.raises(hg.SystemSetupError, match="OpenGL 3.3 found, hybridgen needs 4.3"):
        create_context(0)
    assert asked == [{"backend": "egl", "device_index": 0, "require": MIN_GL_VERSION}] and MIN_GL_VERSION == 430
