"""True geometric displacement (hybridgen/scene/displacement.py) against the analytic height field.

A 4 m plane (z = 0, smooth, UVs u = (x + 1) / 2, v = (y + 1) / 2 in [-0.5, 1.5]) displaced with the periodic
height H(u, v) = 0.5 + 0.4 sin(2 pi u) cos(2 pi v) read at LOCAL coordinates (u = (x + 1) / 2 of the vertex's own
position; the image repeats), strength s: every vertex of the subdivided plane - wherever Catmull-Clark puts it;
a lone quad's grid is not uniform and its rim rounds - lies on the surface z = f(x, y) = s (H - 0.5). Seen from
straight above, the label depth at each pixel centre is where that pixel's ray meets z = f (solved by Newton
iterations), and the normal is (-f_x, -f_y, 1) normalised. The mesh approximates f by triangles of edge about
4 m / 2^L (L = subdiv_level, 7: 3.1 cm) with vertices on f (up to the 256^2 image's bilinear error: 1.2e-5 m):
linear interpolation over a right triangle of legs e is off by at most M R^2 / 2, R = e / sqrt(2) its circumradius
and M = s 0.4 pi^2 = 0.79 / m the largest curvature of f, i.e. 1.9e-4 m for e = 3.1 cm, a little more along tilted
rays (measured: 1.7e-4 m); interpolated vertex normals are off by at most about e M / 2 = 0.012 rad (measured: max
0.0014, median 0.0008 rad: the corner-angle weighted normals of a near-regular grid are better). A
trimesh ray cast on the displaced mesh and Mitsuba's own ray tracer (the color view's scene) meet the same surface
as the raster depth.
"""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.config.displacement_config import displacement_from_config
from hybridgen.errors import ConfigError
from hybridgen.scene.displacement import Displacement, displace_object
from hybridgen.scene.displacement_texture import ImageHeight

STRENGTH, LEVEL, SIZE = 0.2, 7, 64
FOCAL, HEIGHT = 78.0, 2.5
CAM2WORLD = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, HEIGHT], [0, 0, 0, 1]])


def _height(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return 0.5 + 0.4 * np.sin(2 * np.pi * u) * np.cos(2 * np.pi * v)


def _image(n: int = 256) -> np.ndarray:
    centres = (np.arange(n) + 0.5) / n
    u, v = np.meshgrid(centres, 1.0 - centres)  # row 0 is the top: v near 1
    return _height(u, v)


def _f(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height and its x, y derivatives of the displaced plane (u = (x + 1) / 2: du/dx = 1/2)."""
    u, v = (x + 1) / 2, (y + 1) / 2
    z = STRENGTH * (_height(u, v) - 0.5)
    fx = STRENGTH * 0.4 * np.pi * np.cos(2 * np.pi * u) * np.cos(2 * np.pi * v)
    fy = -STRENGTH * 0.4 * np.pi * np.sin(2 * np.pi * u) * np.sin(2 * np.pi * v)
    return z, fx, fy


def _plane(name: str = "plane", half: float = 1.0) -> hg.MeshObject:
    vertices = half * np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    return hg.MeshObject(name, vertices, [[0, 1, 2], [0, 2, 3]], vertex_normals=np.tile([0.0, 0, 1], (4, 1)),
                         uvs=(vertices[:, :2] + 1) / 2, category_id=1)


def _scene(obj: hg.MeshObject) -> hg.Scene:
    scene = hg.Scene()
    scene.add(obj)
    K = np.array([[FOCAL, 0, SIZE / 2 - 0.5], [0, FOCAL, SIZE / 2 - 0.5], [0, 0, 1]])
    scene.camera.intrinsics = hg.Intrinsics(K, SIZE, SIZE)
    scene.camera.add_keypoint(CAM2WORLD)
    return scene


def _rays() -> tuple[np.ndarray, np.ndarray]:
    """World ray directions (camera z component 1) of every pixel centre, and the camera origin."""
    u, v = np.meshgrid(np.arange(SIZE, dtype=float), np.arange(SIZE, dtype=float))
    cam = np.stack([(u - (SIZE / 2 - 0.5)) / FOCAL, (v - (SIZE / 2 - 0.5)) / FOCAL, np.ones_like(u)], -1)
    return cam @ CAM2WORLD[:3, :3].T, CAM2WORLD[:3, 3]


def _analytic_depth() -> tuple[np.ndarray, np.ndarray]:
    """Camera-z depth where each pixel-centre ray meets z = f(x, y), and the surface normal there (world)."""
    d, o = _rays()
    t = np.full(d.shape[:2], HEIGHT)  # depth of the flat plane
    for _ in range(20):  # Newton on g(t) = o_z + t d_z - f(o_xy + t d_xy)
        p = o + t[..., None] * d
        z, fx, fy = _f(p[..., 0], p[..., 1])
        g = p[..., 2] - z
        t = t - g / (d[..., 2] - fx * d[..., 0] - fy * d[..., 1])
    p = o + t[..., None] * d
    _, fx, fy = _f(p[..., 0], p[..., 1])
    n = np.stack([-fx, -fy, np.ones_like(fx)], -1)
    return t, n / np.linalg.norm(n, axis=-1, keepdims=True)


@pytest.fixture(scope="module")
def displaced() -> hg.MeshObject:
    obj = _plane(half=2.0)
    displace_object([obj], Displacement(ImageHeight(_image()), strength=STRENGTH, subdiv_level=LEVEL, simplify=0))
    return obj


def test_displaced_plane_depth_and_normals_match_the_height_field(gl_context, displaced):
    assert len(displaced.faces) == 2 * 4 ** LEVEL  # the two triangles were one quad (recovered), now 4^L quads
    labels = hg.RasterView(_scene(displaced)).render(CAM2WORLD, ["depth", "normals"], normals_space="world")
    depth, normals = labels["depth"].astype(np.float64), labels["normals"].astype(np.float64)
    expected_depth, expected_normals = _analytic_depth()
    inside = np.isfinite(depth)
    assert inside.mean() > 0.8  # the plane fills the view but for its rim
    assert np.abs(depth - expected_depth)[inside].max() < 3e-4  # bound ~2.1e-4 m (module docstring)
    assert np.abs(depth - HEIGHT)[inside].max() > 0.05  # the surface really moved (amplitude 0.08 m)
    angle = np.arccos(np.clip(np.sum(normals * expected_normals, -1), -1, 1))[inside]
    assert angle.max() < 0.005 and np.median(angle) < 0.002  # at most about 0.012 rad (module docstring)
    flat_angle = np.arccos(np.clip(expected_normals[..., 2], -1, 1))[inside]
    assert flat_angle.max() > 0.2  # the analytic normals tilt by up to ~0.25 rad in view: not trivial


def test_trimesh_and_mitsuba_meet_the_displaced_surface_where_the_labels_do(gl_context, displaced):
    import trimesh

    from hybridgen.render.pathtrace.path_trace import PathTraceView, mitsuba_pixel_centre_depth

    scene = _scene(displaced)
    depth = hg.RasterView(scene).render(CAM2WORLD, ["depth"])["depth"].astype(np.float64)
    mesh = trimesh.Trimesh(displaced.world_vertices(), displaced.faces, process=False)
    d, o = _rays()
    hits, rays, _ = mesh.ray.intersects_location(np.tile(o, (SIZE * SIZE, 1)), d.reshape(-1, 3),
                                                 multiple_hits=False)
    cast = np.full(SIZE * SIZE, np.inf)
    cast[rays] = (hits - o) @ CAM2WORLD[:3, 2]
    cast = cast.reshape(SIZE, SIZE)
    inside = np.isfinite(depth) & np.isfinite(cast)
    assert inside.mean() > 0.8
    assert np.abs(depth[inside] - cast[inside]).max() < 2e-5
    traced = mitsuba_pixel_centre_depth(PathTraceView(scene, hg.PathTraceSettings(samples=1)), CAM2WORLD)
    both = inside & np.isfinite(traced)
    assert both.mean() > 0.8 and np.abs(traced[both] - depth[both]).max() < 2e-5


def test_instances_share_one_displaced_mesh_and_local_coordinates_match_uvs():
    first, second = _plane("a"), _plane("b")
    second.vertices, second.faces, second.uvs, second.vertex_normals = \
        first.vertices, first.faces, first.uvs, first.vertex_normals  # two placements of one model
    image = ImageHeight(_image(32))
    done: dict = {}
    for obj in (first, second):
        displace_object([obj], Displacement(image, strength=STRENGTH, subdiv_level=2, texture_coords="UV"), done)
    assert first.vertices is second.vertices and first.faces is second.faces
    # without smoothing the subdivided vertices stay where their UVs say: LOCAL x, y in [-1, 1] read the image as
    # u = (x + 1) / 2, the same as these UVs (Catmull-Clark moves the positions off their linear UVs)
    local, by_uv = _plane("c"), _plane("d")
    displace_object([local], Displacement(image, strength=STRENGTH, subdiv_level=2, subdivision="SIMPLE"))
    displace_object([by_uv], Displacement(image, strength=STRENGTH, subdiv_level=2, subdivision="SIMPLE",
                                          texture_coords="UV"))
    np.testing.assert_allclose(local.vertices, by_uv.vertices, atol=1e-12)
    assert np.abs(local.vertices - first.vertices).max() > 0.01
    untouched = _plane("e")
    displace_object([untouched], Displacement(image, subdiv_level=2, min_vertices_for_subdiv=3))
    assert len(untouched.faces) == 2  # more vertices than min_vertices_for_subdiv: not subdivided (BlenderProc)


def test_config_errors_name_the_key():
    with pytest.raises(ConfigError, match="displace.strenght"):
        displacement_from_config({"texture": "x.png", "strenght": 1})
    with pytest.raises(ConfigError, match="procedural"):
        displacement_from_config({"texture": 3})
    with pytest.raises(ConfigError, match="displace.subdiv_level"):
        displacement_from_config({"texture": __file__, "subdiv_level": 12})


def test_entity_manipulator_displaces_selected_objects(write_config, tmp_path):
    from PIL import Image

    from tests.sampling.test_placement import _context

    Image.fromarray(np.full((4, 4), 255, np.uint8)).save(tmp_path / "white.png")  # h = 1 everywhere
    context, _ = _context(f"""
modules:
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 2, name: floor, category_id: 1}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 2, name: other, category_id: 2}}
  - name: manipulators.EntityManipulator
    config:
      selector: {{name: floor}}
      displace: {{texture: {tmp_path}/white.png, strength: 0.3, subdiv_level: 1}}
""", write_config)
    floor, other = context.scene.by_name("floor"), context.scene.by_name("other")
    assert len(other.faces) == 2 and np.all(other.vertices[:, 2] == 0)
    assert len(floor.faces) == 8  # one Catmull-Clark level: four quads
    np.testing.assert_allclose(floor.vertices[:, 2], 0.5 * 0.3)  # (1 - mid_level 0.5) x strength along +z
    # Blender 4.2's level 1 of its 2 m plane (bpy): x, y in {0, +-0.671875 (corners), +-0.916667 (edge middles)}
    assert np.allclose(np.unique(np.abs(floor.vertices[:, :2]).round(6)), [0.0, 0.671875, 0.916667], atol=1e-6)
