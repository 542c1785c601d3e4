"""Per-vertex colors and alpha cut-outs reach both renderers.

A 2 m quad seen from straight above, red at x = -1 and blue at x = +1: both the raster albedo and Mitsuba
interpolate the colors linearly over the face, so the albedo at x is lerp(red, blue, (x + 1) / 2) and a sun of
irradiance E from straight above makes the Lambertian radiance albedo / pi * E. PLY vertex colors are 8-bit
sRGB, decoded to linear as Blender decodes byte color attributes.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.render.raster.albedo_pass import AlbedoPass
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

RED, BLUE = np.array([0.8, 0.05, 0.05]), np.array([0.05, 0.1, 0.7])
SUN = 2.0
WIDTH = 24
K = np.array([[20.0, 0, (WIDTH - 1) / 2], [0, 20.0, (WIDTH - 1) / 2], [0, 0, 1]])  # 0.15 m pixels 3 m away
TOP_DOWN = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 3.0], [0, 0, 0, 1]])


def _split_quad() -> hg.MeshObject:
    vertices = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]
    colors = [RED, BLUE, BLUE, RED]
    return hg.MeshObject("quad", vertices, [[0, 1, 2], [0, 2, 3]], vertex_colors=colors,
                         material=hg.Material(base_color=(0.5, 0.5, 0.5, 1), specular=0.0,
                                              base_color_from_vertices=True))


def _scene(*objects: hg.MeshObject) -> hg.Scene:
    scene = hg.Scene()
    for obj in objects:
        scene.add(obj)
    scene.world.strength = 0.0
    scene.world.color = (0.0, 0.0, 0.0)
    scene.add_light(hg.Light("sun", "SUN", energy=SUN))  # the identity pose shines along -z
    scene.camera.intrinsics = hg.Intrinsics(K, WIDTH, WIDTH)
    scene.camera.add_keypoint(TOP_DOWN)
    return scene


def _pixel_x(depth: float = 3.0) -> np.ndarray:
    """World x of each pixel column's centre (= -y of each row's) on a plane ``depth`` below the camera."""
    return (np.arange(WIDTH) - K[0, 2]) / K[0, 0] * depth


def test_vertex_colors_interpolate_in_albedo_and_color(gl_context):
    scene = _scene(_split_quad())
    albedo = AlbedoPass(hg.RasterView(scene)).render(TOP_DOWN, background=(0, 0, 0))
    x = _pixel_x()
    inside = np.abs(x) < 1 - 1e-6
    weight = ((x + 1) / 2)[:, None]
    expected = (1 - weight) * RED + weight * BLUE
    rows = np.flatnonzero(inside)  # the quad is as wide in y
    np.testing.assert_allclose(albedo[rows][:, inside], np.broadcast_to(expected[inside], albedo[rows][:, inside].shape),
                               atol=1e-5)
    color = PathTraceView(scene, PathTraceSettings(samples=4, max_bounces=1), variant=choose_variant()).render(
        TOP_DOWN, seed=1)
    # a pixel's filter integrates the linear ramp symmetrically: its mean is the value at its centre (pixels
    # two footprints away from the quad's edges, whose reconstruction filter stays on the quad)
    core = np.abs(x) < 0.7
    rows = np.flatnonzero(core)
    np.testing.assert_allclose(color[rows][:, core].mean(axis=0), expected[core] / math.pi * SUN, rtol=0.01,
                               atol=0.003)
    # not the object's single base color: the red end and the blue end differ
    ends = color[rows][:, np.flatnonzero(core)[[0, -1]]].mean(axis=0)
    assert ends[0, 0] > 2 * ends[1, 0] and ends[1, 2] > 2 * ends[0, 2]


def test_ply_vertex_colors_load_linear_and_a_base_color_override_removes_them(tmp_path):
    from hybridgen.config.material_config import apply_material_config

    mesh = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], process=False)
    mesh.visual.vertex_colors = [[255, 0, 0, 255], [0, 0, 255, 255], [188, 188, 188, 255]]
    mesh.export(tmp_path / "tri.ply")
    [obj] = hg.load_objects(tmp_path / "tri.ply")
    assert obj.material.base_color_from_vertices
    # sRGB 188 decodes to 0.5029 (IEC 61966-2-1)
    np.testing.assert_allclose(obj.vertex_colors, [[1, 0, 0], [0, 0, 1], [0.50289] * 3], atol=1e-5)
    overridden = apply_material_config(obj.material, {"base_color": [0.1, 0.2, 0.3]})
    assert not overridden.base_color_from_vertices


def test_alpha_clip_cuts_the_surface_out_of_albedo_and_color(gl_context):
    """A quad at z = 0.5 whose alpha map is opaque on its left half, over a green floor: where alpha is
    0 both renderers see the floor, where it is 1 the quad; BLEND alpha leaves the albedo opaque."""
    floor = hg.MeshObject("floor", [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]],
                          material=hg.Material(base_color=(0.1, 0.6, 0.1, 1), specular=0.0))
    alpha = np.zeros((4, 8), np.uint8)
    alpha[:, :4] = 255  # u < 0.5 opaque
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    cut = hg.MeshObject("cut", [[-1, -1, 0.5], [1, -1, 0.5], [1, 1, 0.5], [-1, 1, 0.5]], [[0, 1, 2], [0, 2, 3]],
                        uvs=uvs, material=hg.Material(base_color=(0.7, 0.1, 0.1, 1), specular=0.0,
                                                      alpha_texture=alpha, alpha_mode="CLIP"))
    scene = _scene(floor, cut)
    albedo = AlbedoPass(hg.RasterView(scene)).render(TOP_DOWN, background=(0, 0, 0))
    x = _pixel_x(2.5)  # on the quad's plane, 2.5 m below the camera
    rows = np.flatnonzero(np.abs(x) < 0.75)
    left, right = (x > -0.75) & (x < -0.25), (x > 0.25) & (x < 0.75)  # two pixels off every edge
    np.testing.assert_allclose(albedo[rows][:, left], np.broadcast_to([0.7, 0.1, 0.1], albedo[rows][:, left].shape))
    np.testing.assert_allclose(albedo[rows][:, right], np.broadcast_to([0.1, 0.6, 0.1], albedo[rows][:, right].shape))
    # Mitsuba: camera rays pass the cut-out. Its shadow rays do not (the path integrator has no transparent
    # shadows), so the sun comes in at 70 degrees from +x, past the quad's edge, to light the floor below it.
    slant = math.radians(70)
    scene.lights[0].local2world = np.array([[math.cos(slant), 0, math.sin(slant), 0], [0, 1, 0, 0],
                                            [-math.sin(slant), 0, math.cos(slant), 0], [0, 0, 0, 1.0]])
    color = PathTraceView(scene, PathTraceSettings(samples=4, max_bounces=1), variant=choose_variant()).render(
        TOP_DOWN, seed=1)
    lit = SUN * math.cos(slant) / math.pi
    np.testing.assert_allclose(color[rows][:, left].mean(axis=(0, 1)), np.array([0.7, 0.1, 0.1]) * lit, rtol=0.02)
    np.testing.assert_allclose(color[rows][:, right].mean(axis=(0, 1)), np.array([0.1, 0.6, 0.1]) * lit, rtol=0.02)
    cut.material = hg.Material(base_color=(0.7, 0.1, 0.1, 1), specular=0.0, alpha_texture=alpha)  # BLEND
    blended = AlbedoPass(hg.RasterView(scene)).render(TOP_DOWN, background=(0, 0, 0))
    np.testing.assert_allclose(blended[rows][:, right], np.broadcast_to([0.7, 0.1, 0.1], blended[rows][:, right].shape))


@pytest.mark.parametrize("alpha, drawn", [(0.3, False), (0.6, True)])
def test_constant_alpha_clip_is_all_or_nothing(gl_context, alpha, drawn):
    quad = _split_quad()
    quad.material.alpha, quad.material.alpha_mode = alpha, "CLIP"
    albedo = AlbedoPass(hg.RasterView(_scene(quad))).render(TOP_DOWN, background=(0, 0, 0))
    assert (albedo[WIDTH // 2, WIDTH // 2].sum() > 0) == drawn


def test_alpha_clip_cuts_labels_blend_does_not(gl_context):
    """Labels of the half-cut quad over the floor: depth and instance ids show the floor through the cut
    (alpha below 0.5), the quad elsewhere; a BLEND material with the same map keeps the whole quad."""
    floor = hg.MeshObject("floor", [[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]])
    alpha = np.zeros((4, 8), np.uint8)
    alpha[:, :4] = 200
    cut = hg.MeshObject("cut", [[-1, -1, 0.5], [1, -1, 0.5], [1, 1, 0.5], [-1, 1, 0.5]], [[0, 1, 2], [0, 2, 3]],
                        uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float),
                        material=hg.Material(alpha_texture=alpha, alpha_mode="CLIP"))
    scene = _scene(floor, cut)
    x = _pixel_x(2.5)
    rows = np.flatnonzero(np.abs(x) < 0.75)
    left, right = (x > -0.75) & (x < -0.25), (x > 0.25) & (x < 0.75)
    labels = hg.RasterView(scene).render(TOP_DOWN, passes=("depth", "instance_segmaps"))
    ids, depth = labels["instance_segmaps"][rows], labels["depth"][rows]
    assert np.all(ids[:, left] == cut.instance_id) and np.all(ids[:, right] == floor.instance_id)
    np.testing.assert_allclose(depth[:, left], 2.5, atol=1e-5)
    np.testing.assert_allclose(depth[:, right], 3.0, atol=1e-5)
    cut.material = hg.Material(alpha_texture=alpha)  # BLEND: labels see the surface
    labels = hg.RasterView(scene).render(TOP_DOWN, passes=("instance_segmaps",))
    assert np.all(labels["instance_segmaps"][rows][:, left | right] == cut.instance_id)
    cut.material = hg.Material(alpha=0.3, alpha_mode="CLIP")  # a constant below 0.5: gone from labels
    labels = hg.RasterView(scene).render(TOP_DOWN, passes=("instance_segmaps",))
    assert not np.any(labels["instance_segmaps"] == cut.instance_id)
