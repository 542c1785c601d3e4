"""bproc.object.create_primitive gives Blender's meshes and UV maps (hybridgen/scene/blender_primitives.py, measured
with bpy 4.2: tests/scene/test_blender_primitives.py): a cube textured with a UV ramp (texel (i, j) holds i and j)
and drawn from above shows each texel where Blender's UV map puts it on the top face - the face's stored Blender
corner UVs, interpolated at each pixel's analytic hit point; the UV sphere has Blender's 32 x 16 facets; the
operator's arguments and scale behave as Blender's."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.raster.albedo_pass import AlbedoPass
from writer_session import bproc  # noqa: F401 - the fixture

TABLE = json.loads((Path(__file__).parents[1] / "scene" / "data" / "blender_primitives.json").read_text())
N = 256  # ramp texels per axis


def _srgb_byte(linear: np.ndarray) -> np.ndarray:
    """Linear values back to (fractional) 8-bit sRGB codes."""
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(np.maximum(linear, 0), 1 / 2.4) - 0.055)
    return srgb * 255.0


def test_textured_cube_shows_texels_where_blender_puts_them(gl_context, bproc) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE", location=[0.2, -0.1, 0.0], rotation=[0.0, 0.0, 0.3])
    part = cube.parts[0]
    ramp = np.zeros((N, N, 3), np.uint8)
    ramp[..., 0] = np.arange(N)[None, :]  # column i (u = (i + 0.5) / N)
    ramp[..., 1] = np.arange(N)[::-1, None]  # row j from the bottom (v = (j + 0.5) / N)
    part.material = hg.Material(base_color_texture=ramp)
    scene = hg.Scene()
    scene.add(part)
    part.local2world = cube.get_local2world_mat()
    size = (96, 72)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.5, *size, clip_start=0.01)
    pose = np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV axes looking down world -Z, image up = world +Y
    pose[:3, 3] = [0.2, -0.1, 9.0]
    scene.camera.add_keypoint(pose)
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0.0, 0.0, 0.0))
    # the analytic hit of each pixel centre's ray on the top face z = 1, in the cube's local frame
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    v, u = np.mgrid[0:size[1], 0:size[0]].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], -1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    hits = pose[:3, 3] + rays * ((1.0 - pose[2, 3]) / rays[..., 2:])
    local = (hits - cube.get_location()) @ cube.get_local2world_mat()[:3, :3]  # rotation only: the inverse
    top = next(p for p in TABLE["cube"]["sample"] if np.allclose(np.asarray(p["corners"])[:, 2], 1.0))
    corners, corner_uvs = np.asarray(top["corners"]), np.asarray(top["uvs"])
    # Blender's UVs on the square face are affine in x, y: fit them exactly from its four corners
    design = np.c_[corners[:, :2], np.ones(4)]
    coefficients, residual, *_ = np.linalg.lstsq(design, corner_uvs, rcond=None)
    assert np.allclose(design @ coefficients, corner_uvs)
    expected = np.c_[local[..., :2].reshape(-1, 2), np.ones(local[..., 0].size)] @ coefficients
    inside = (np.abs(local[..., :2]) < 0.95).all(-1).reshape(-1)
    got = _srgb_byte(albedo[..., :2].reshape(-1, 2)[inside])
    texel = expected[inside] * N - 0.5  # the (fractional) texel index bilinear filtering returns there
    assert inside.sum() > 400
    # within half a texel (1/512 in u, v; 16 mm on the 2 m face): llvmpipe's sRGB decode of the 8-bit codes is
    # within 0.4 of a code of the exact curve (the same at 1.5 or 0.3 texels per pixel); a texel off is a failure
    np.testing.assert_allclose(got, texel, atol=0.5)
    assert np.ptp(texel[:, 0]) > 40 and np.ptp(texel[:, 1]) > 40  # the face spans 64 x 64 texels


def test_sphere_cylinder_cone_have_blenders_facets_and_arguments(bproc) -> None:  # noqa: F811
    sphere = bproc.object.create_primitive("SPHERE")
    vertices = np.unique(np.concatenate([p.vertices for p in sphere.parts]).round(6), axis=0)
    assert len(vertices) == TABLE["uv_sphere"]["vertices"] == 482
    assert sphere.parts[0].vertex_normals is None  # flat-shaded, as Blender's
    cone = bproc.object.create_primitive("CONE", vertices=5, radius1=0.5, radius2=0.25, depth=1.0,
                                         end_fill_type="TRIFAN", scale=[2.0, 1.0, 1.0])
    points = np.concatenate([p.vertices for p in cone.parts])
    assert np.allclose(cone.get_scale(), 1.0)  # the operator's scale goes into the mesh, as Blender's
    assert np.isclose(points[:, 0].max(), 2 * 0.5 * np.sin(2 * np.pi / 5)) and np.isclose(points[:, 2].max(), 0.5)
    plane = bproc.object.create_primitive("PLANE", scale=[2.0, 3.0, 1.0])
    assert np.allclose(plane.get_scale(), [2.0, 3.0, 1.0])  # ... but a plane's object is scaled (BlenderProc)
    bare = bproc.object.create_primitive("CUBE", calc_uvs=False)
    assert bare.parts[0].uvs is None and len(bare.parts[0].vertices) == 8
    with pytest.raises(Exception, match="MONKEY.*not supported"):
        bproc.object.create_primitive("MONKEY")
    with pytest.raises(Exception, match="primitive_cone_add takes radius1"):
        bproc.object.create_primitive("CONE", radius=2.0)
