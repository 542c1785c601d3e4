"""MeshObject.add_modifier / add_displace_modifier and bproc.material.create_procedural_texture through the bproc
API: displacement by a known texture moves every vertex by strength x (t - mid_level) along its normal and the
rendered depth and color see it; subdivision before displacement as BlenderProc decides it (Blender's
Catmull-Clark limit of a 2 m cube: 98 vertices, face centres 0.8395 m - bpy 4.2); Solidify of a unit square;
BlenderProc's texture names, random pattern choice and one-line errors."""
from __future__ import annotations

import random

import numpy as np
import pytest
import trimesh

from writer_session import bproc  # noqa: F401 - the fixture


def _down(x: float, y: float, z: float) -> np.ndarray:
    pose = np.eye(4)  # Blender camera axes: looking along world -Z, image up = world +Y
    pose[:3, 3] = [x, y, z]
    return pose


def _ramp(strength_axis: str = "HORIZONTAL"):
    from hybridgen.bproc.procedural_texture import ProceduralTexture

    texture = ProceduralTexture("ramp", "BLEND")  # Blender's LINEAR gradient: t = (1 + x) / 2
    texture.use_flip_axis = strength_axis
    return texture


def test_displacement_by_a_known_texture_moves_vertices_and_depth(gl_context, bproc) -> None:  # noqa: F811
    plane = bproc.object.create_primitive("PLANE")  # 2 m, z = 0, normal +z
    plane.add_modifier("SUBSURF", render_levels=3, subdivision_type="SIMPLE")  # a flat 9 x 9 grid
    flat = np.concatenate([part.vertices for part in plane.parts])
    assert len(np.unique(flat, axis=0)) == 81 and np.all(flat[:, 2] == 0)
    plane.add_modifier("DISPLACE", texture=_ramp(), strength=0.4, mid_level=0.3)
    moved = np.unique(np.concatenate([part.vertices for part in plane.parts]), axis=0)
    assert len(moved) == 81
    assert np.allclose(moved[:, 2], 0.4 * ((1 + moved[:, 0]) / 2 - 0.3), atol=1e-12)  # exactly, along +z
    assert np.allclose(np.unique(moved[:, 0]), np.linspace(-1, 1, 9))  # nothing moved sideways
    bproc.camera.add_camera_pose(_down(0.2, 0.0, 4.0))
    bproc.renderer.enable_depth_output(activate_antialiasing=False)
    depth = bproc.renderer.render()["depth"][0]
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    a, b = (u - K[0, 2]) / K[0, 0], -(v - K[1, 2]) / K[1, 1]  # ray direction per metre of depth
    # the displaced plane z = 0.08 + 0.2 x meets the ray (0.2 + a t, b t, 4 - t) at t = (3.92 - 0.04) / (1 + 0.2 a)
    t = 3.88 / (1 + 0.2 * a)
    inside = (np.abs(0.2 + a * t) < 0.98) & (np.abs(b * t) < 0.98)
    assert inside.sum() > 100
    assert np.allclose(depth[inside], t[inside], atol=1e-4)


def test_displaced_geometry_reaches_the_color_render(bproc) -> None:  # noqa: F811
    plane = bproc.object.create_primitive("PLANE", size=1.0)  # x, y in -0.5..0.5
    plane.add_modifier("DISPLACE", strength=0.8, mid_level=0.0, direction="X")  # no texture: t = 1, 0.8 m along +x
    assert np.allclose(plane.get_bound_box()[:, 0].min(), 0.3)
    bproc.camera.add_camera_pose(_down(0.0, 0.0, 4.0))
    bproc.renderer.set_max_amount_of_samples(1)
    bproc.renderer.set_output_format(enable_transparency=True)
    alpha = bproc.renderer.render()["colors"][0][..., 3]
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    x, y = (u - K[0, 2]) / K[0, 0] * 4.0, -(v - K[1, 2]) / K[1, 1] * 4.0
    covered = (np.abs(x - 0.8) < 0.5) & (np.abs(y) < 0.5)
    assert 0 < covered.sum() and np.array_equal(alpha, np.where(covered, 255, 0))


def test_add_displace_modifier_subdivides_small_meshes_first(bproc) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE")  # 8 vertices, 2 m
    texture = bproc.material.create_procedural_texture("clouds")
    cube.add_displace_modifier(texture, strength=0.0, subdiv_level=2)  # strength 0: the subdivided surface itself
    vertices = np.unique(np.concatenate([part.vertices for part in cube.parts]), axis=0)
    assert len(vertices) == 98 and np.abs(vertices).max() == pytest.approx(0.8395062, abs=1e-6)  # Blender's limit
    big = bproc.object.create_primitive("CUBE", location=[5, 0, 0])
    big.add_displace_modifier(texture, strength=0.3, min_vertices_for_subdiv=7)  # 8 > 7: no subdivision
    moved = np.unique(np.concatenate([part.vertices for part in big.parts]), axis=0)
    corners = np.array([(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    expected = corners + corners / np.sqrt(3) * (0.3 * (texture.displacement(corners) - 0.5))[:, None]
    assert len(moved) == 8 and np.allclose(np.sort(moved, axis=0), np.sort(expected, axis=0), atol=1e-12)


def test_solidify_a_unit_square(bproc) -> None:  # noqa: F811
    square = bproc.object.create_primitive("PLANE", size=1.0, location=[0, 0, 2])
    square.add_modifier("SOLIDIFY", thickness=0.05)
    vertices, faces = square.local_mesh()
    shell = trimesh.Trimesh(vertices, faces)  # welds the split vertices
    assert len(shell.vertices) == 8 and len(shell.faces) == 12  # 6 quads
    assert shell.is_watertight and shell.volume == pytest.approx(0.05)
    assert np.allclose(square.get_bound_box()[:, 2].min(), 2 - 0.05) and np.allclose(square.get_bound_box()[:, 2].max(), 2)


def test_procedural_textures_as_blenderproc_makes_them(bproc) -> None:  # noqa: F811
    from hybridgen.bproc.procedural_texture import PATTERNS
    from hybridgen.errors import InputError

    first = bproc.material.create_procedural_texture("CLOUDS")
    second = bproc.material.create_procedural_texture("clouds")
    assert (first.name, second.name, first.type) == ("ct_CLOUDS", "ct_CLOUDS.001", "CLOUDS")
    assert first.noise_scale == 0.25 and first.noise_depth == 2 and first.noise_basis == "BLENDER_ORIGINAL"
    random.seed(7)
    expected = random.Random(7).choice(PATTERNS)
    assert bproc.material.create_procedural_texture().type == expected  # Python's random.choice, its draw
    assert random.random() == pytest.approx(_second_draw(7))
    color = first.evaluate((0.1, 0.2, 0.3))
    assert len(color) == 4 and list(color)[:3] == [0, 0, 0] and 0 < color[3] < 1  # Blender's (0, 0, 0, intensity)
    first.noise_scale = 1.0
    assert first.noise_scale == 1.0
    with pytest.raises(InputError, match="no such pattern"):
        bproc.material.create_procedural_texture("BLEND")  # not among BlenderProc's patterns
    with pytest.raises(InputError, match="noise_basis must be one of"):
        first.noise_basis = "SIMPLEX"
    with pytest.raises(InputError, match="has no setting 'turbulence'"):
        first.turbulence = 3.0


def _second_draw(seed: int) -> float:
    generator = random.Random(seed)
    generator.choice(range(9))
    return generator.random()


def test_modifier_errors_are_one_line(bproc) -> None:  # noqa: F811
    from hybridgen.errors import InputError

    cube = bproc.object.create_primitive("CUBE")
    before = cube.parts[0].vertices
    with pytest.raises(InputError, match=r"add_modifier\('BEVEL'\) is not supported by hybridgen yet"):
        cube.add_modifier("BEVEL", width=0.1)
    with pytest.raises(InputError, match="has no attribute 'thicknes'"):
        cube.add_modifier("SOLIDIFY", thicknes=0.1)
    with pytest.raises(InputError, match="solidify_mode='NON_MANIFOLD'.*not supported"):
        cube.add_modifier("SOLIDIFY", solidify_mode="NON_MANIFOLD")
    with pytest.raises(InputError, match="boundary_smooth"):
        cube.add_modifier("SUBSURF", boundary_smooth="PRESERVE_CORNERS")
    assert cube.parts[0].vertices is before  # nothing applied


def test_simplify_limits_subdivision_levels(bproc) -> None:  # noqa: F811
    def vertex_count(obj) -> int:
        return len(np.unique(np.concatenate([part.vertices for part in obj.parts]), axis=0))

    capped = bproc.object.create_primitive("CUBE")
    capped.add_modifier("SUBSURF", render_levels=5)  # BlenderProc's init limits renders to 3 levels
    assert vertex_count(capped) == 386  # Blender's cube at level 3
    bproc.renderer.set_simplify_subdivision_render(1)
    once = bproc.object.create_primitive("CUBE")
    once.add_modifier("SUBSURF", render_levels=2)
    assert vertex_count(once) == 26
    bproc.renderer.set_simplify_subdivision_render(0)  # no limit
    four = bproc.object.create_primitive("CUBE")
    four.add_modifier("SUBSURF", render_levels=4)
    assert vertex_count(four) == 6 * 16 * 16 + 2


def test_add_displace_modifier_with_an_image_texture_equals_blender(bproc, tmp_path) -> None:  # noqa: F811
    """A 4 x 4 RGB image of bproc.loader.load_texture on Blender's 2 m plane: Blender 4.2's displaced vertices
    (tests/scene/data/blender_displace_image.json, tools/blender_displace_image.py)."""
    import json
    from pathlib import Path

    from PIL import Image

    table = json.loads((Path(__file__).parents[1] / "scene" / "data" / "blender_displace_image.json").read_text())
    case = table["cases"]["rgb catmull-clark 3"]
    Image.fromarray(np.asarray(table["images"]["rgb.png"], dtype=np.uint8)).save(tmp_path / "rgb.png")
    texture = bproc.loader.load_texture(str(tmp_path / "rgb.png"))[0]
    plane = bproc.object.create_primitive("PLANE")
    plane.add_displace_modifier(texture, mid_level=case["mid_level"], strength=case["strength"],
                                subdiv_level=case["levels"])
    ours = np.unique(np.concatenate([part.vertices for part in plane.parts]), axis=0)
    blender = np.array(case["vertices"])
    assert len(ours) == len(blender)
    distance = np.linalg.norm(ours[:, None] - blender[None], axis=2).min(axis=1)
    assert distance.max() < 2e-6 and np.ptp(blender[:, 2]) > 0.1
