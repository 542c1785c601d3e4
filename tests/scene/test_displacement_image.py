"""Displacement by an image, and by a procedural texture of ``sampler.Texture``, through the one implementation
(hybridgen/scene/displacement.py: Catmull-Clark, Displace, textures of scene/displacement_texture.py) against
Blender 4.2: the stored table (tests/scene/data/blender_displace_image.json, written by
``tools/blender_displace_image.py --store``) holds 4 x 4 images (8-bit grey, 8-bit RGB, 16-bit grey), a 2 m quad
plane in an OBJ file's x-y plane, and per case the vertices (Blender's mesh frame, the file's coordinates) of that
plane after Blender's Subdivision Surface + Displace (LOCAL coordinates) with the image - SIMPLE subdivision for
the sampling alone (bilinear between texel centres, repeating past [-1, 1], the mean of R, G, B, 16-bit sRGB
decoded), Catmull-Clark for the whole modifier stack. The v1 config path (a BlenderProc 1.x config: ObjectLoader,
TextureLoader, EntityManipulator's cf_add_displace_modifier_with_texture with getter.Texture) and the bproc path
(add_displace_modifier with bproc.loader.load_texture) give Blender's vertices; a CLOUDS texture of sampler.Texture
displaces by exactly scene/procedural_texture's values, whose statistics are Blender's (test_procedural_texture)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hybridgen.scene.displacement import Displacement, displaced_parts
from hybridgen.scene.displacement_texture import ImageHeight, ProceduralHeight
from hybridgen.scene.frames import Y_UP_TO_Z_UP
from hybridgen.scene.mesh_object import MeshObject
from hybridgen.scene.procedural_texture import displacement_value, settings_of
from tests.config.test_blenderproc_modules import run_config_text

TABLE = json.loads((Path(__file__).parent / "data" / "blender_displace_image.json").read_text())
CASES = TABLE["cases"]


def _inputs(folder: Path) -> Path:
    """The table's images and OBJ plane written into ``folder``; the OBJ's path."""
    for name, values in TABLE["images"].items():
        Image.fromarray(np.asarray(values, dtype=np.uint16 if name.endswith("16.png") else np.uint8)).save(
            folder / name)
    (folder / "plane.obj").write_text(TABLE["plane_obj"])
    return folder / "plane.obj"


def _plane_vertices() -> np.ndarray:
    return np.array([[float(c) for c in line.split()[1:]] for line in TABLE["plane_obj"].splitlines()
                     if line.startswith("v ")])


def _largest_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance from a vertex of either set to the nearest of the other (m); equal counts asserted."""
    assert a.shape == b.shape
    d = np.linalg.norm(a[:, None] - b[None], axis=2)
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


@pytest.mark.parametrize("name", list(CASES))
def test_image_displacement_equals_blenders(tmp_path: Path, name: str) -> None:
    _inputs(tmp_path)
    case = CASES[name]
    plane = MeshObject("Plane", _plane_vertices() * case.get("scale", 1.0), [[0, 1, 2], [0, 2, 3]])
    modifier = Displacement(ImageHeight(str(tmp_path / case["image"]), case.get("colorspace")),
                            strength=case["strength"], mid_level=case["mid_level"], subdiv_level=case["levels"],
                            subdivision=case["subdivision"])
    ours = np.concatenate([part.vertices for part in displaced_parts([plane], modifier)])
    blender = np.array(case["vertices"])
    # 16-bit sRGB: Blender's color management differs from the exact sRGB curve by up to 1e-5
    assert _largest_distance(ours, blender) < (2e-5 if name == "grey16 simple 3" else 2e-6)
    assert np.ptp(blender[:, 2]) > 0.15  # the images really displace


def _grid(folder: Path, n: int = 8, size: float = 7.9, shift: float = 0.137) -> Path:
    """An OBJ of n x n quads over a size x size m square in the file's x-y plane (object 'Plane'), centred at
    (shift, shift): its vertices stay off the noise lattice (noise_scale 0.25), where gradient noise is 0."""
    t = np.linspace(-size / 2, size / 2, n + 1) + shift
    lines = ["o Plane"] + [f"v {x} {y} 0" for y in t for x in t]
    lines += [f"f {r * (n + 1) + c + 1} {r * (n + 1) + c + 2} {(r + 1) * (n + 1) + c + 2} {(r + 1) * (n + 1) + c + 1}"
              for r in range(n) for c in range(n)]
    (folder / "grid.obj").write_text("\n".join(lines) + "\n")
    return folder / "grid.obj"


def _v1_config(tmp_path: Path, texture: object, displace: dict, mesh: Path | None = None) -> str:
    return json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}},
        {"module": "loader.ObjectLoader", "config": {"path": str(mesh or _inputs(tmp_path))}},
        {"module": "loader.TextureLoader", "config": {"path": str(tmp_path / "rgb.png")}},
        {"module": "manipulators.EntityManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"type": "MESH"}},
            "cf_add_displace_modifier_with_texture": {"texture": texture, **displace}}}]})


def test_v1_config_displaces_a_plane_by_an_image_as_blender(tmp_path: Path) -> None:
    case = CASES["rgb catmull-clark 3"]
    texture = {"provider": "getter.Texture", "conditions": {"name": "ct_rgb.png"}, "index": 0}
    context = run_config_text(tmp_path, _v1_config(tmp_path, texture, {
        "subdiv_level": case["levels"], "strength": case["strength"], "mid_level": case["mid_level"]}))
    plane = context.scene.by_name("Plane")
    assert len(plane.vertices) == len(case["vertices"])  # 4^3 quads of the one recovered quad
    # hybridgen's v1 loader turned the OBJ Z-up in the vertices; Blender's mesh keeps the file's coordinates
    in_file = plane.vertices @ Y_UP_TO_Z_UP[:3, :3]
    assert _largest_distance(in_file, np.array(case["vertices"])) < 2e-6


def test_v1_config_with_a_clouds_texture_displaces_by_its_values(tmp_path: Path) -> None:
    texture = {"provider": "sampler.Texture", "textures": ["clouds"]}
    _inputs(tmp_path)
    context = run_config_text(tmp_path, _v1_config(tmp_path, texture, {"subdiv_level": 5, "strength": 0.7},
                                                   _grid(tmp_path)))
    plane = context.scene.by_name("Plane")
    in_file = plane.vertices @ Y_UP_TO_Z_UP[:3, :3]
    assert len(in_file) == 65 * 65  # 8 x 8 quads, 5 levels capped at 3 (BlenderProc's Simplify)
    flat = np.column_stack([in_file[:, :2], np.zeros(len(in_file))])  # the plane before the Displace (z = 0)
    values = displacement_value("CLOUDS", settings_of("CLOUDS"), flat)
    np.testing.assert_allclose(in_file[:, 2], 0.7 * (values - 0.5), atol=1e-12)  # along the normal, file +z
    read = in_file[:, 2] / 0.7 + 0.5
    # Blender's CLOUDS (noise_scale 0.25, depth 2) over random points: mean 0.503, std 0.120, q01..q99 0.24..0.77
    q01, q99 = np.quantile(read, [0.01, 0.99])
    assert abs(read.mean() - 0.503) < 0.02 and abs(read.std() - 0.120) < 0.015
    assert abs(q01 - 0.24) < 0.05 and abs(q99 - 0.77) < 0.05


def test_sampler_texture_draws_blenderprocs_types() -> None:
    from hybridgen.sampling.sampler_table import DrawContext
    from hybridgen.sampling.texture_sampler import PATTERNS, texture

    ctx = DrawContext(np.random.default_rng(3))
    drawn = {texture(ctx).kind for _ in range(200)}
    assert drawn == set(PATTERNS)  # BLEND is Blender's but not among BlenderProc's nine
    voronoi = texture(ctx, textures=["VORONOI"], noise_scale=0.5)
    assert voronoi == ProceduralHeight.of("VORONOI", noise_scale=0.5, noise_intensity=1.0, nabla=0.03)
    points = np.random.default_rng(0).uniform(-3, 3, (50, 3))
    np.testing.assert_allclose(voronoi(points), displacement_value("VORONOI", voronoi.settings, points))
    assert voronoi.settings["noise_scale"] == 0.5 and texture(ctx, textures=["magic"]).kind == "MAGIC"


def test_material_parts_of_one_object_are_displaced_together(tmp_path: Path) -> None:
    """An OBJ object of two quads with two materials is two hybridgen parts but one Blender mesh: the seam's
    vertices move once (the welded mesh's normal and texture value), so the parts stay joined."""
    (tmp_path / "two.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 0 1\n")
    (tmp_path / "two.obj").write_text("mtllib two.mtl\no Strip\nv -0.87 -1.03 0\nv 0.13 -1.03 0\nv 1.13 -1.03 0\n"
                                      "v -0.87 0.97 0\nv 0.13 0.97 0\nv 1.13 0.97 0\n"
                                      "usemtl a\nf 1 2 5 4\nusemtl b\nf 2 3 6 5\n")  # off the noise lattice
    texture = {"provider": "sampler.Texture", "textures": ["CLOUDS"]}
    _inputs(tmp_path)
    context = run_config_text(tmp_path, _v1_config(tmp_path, texture, {"subdiv_level": 2, "strength": 2.0},
                                                   tmp_path / "two.obj"))
    parts = [obj for obj in context.scene.objects if obj.name == "Strip"]
    assert len(parts) == 2
    seams = [p.vertices[np.abs(p.vertices[:, 0] - 0.13) < 1e-9] for p in parts]  # x = 0.13: the shared edge
    assert len(seams[0]) == len(seams[1]) == 5  # the edge's 2^2 + 1 vertices in each part
    first, second = (np.unique(s.round(12), axis=0) for s in seams)
    np.testing.assert_array_equal(first, second)
    assert np.ptp(first[:, 1]) > 0.05  # the seam moved (along file +z: hybridgen's -y)


def test_config_errors_are_one_line(tmp_path: Path) -> None:
    from hybridgen.errors import ConfigError, InputError

    with pytest.raises(ConfigError, match="no procedural texture 'BRICKS'"):
        run_config_text(tmp_path, _v1_config(tmp_path, {"provider": "sampler.Texture", "textures": ["BRICKS"]}, {}))
    with pytest.raises((ConfigError, InputError), match="cf_add_displace_modifier_with_texture|displace.texture"):
        run_config_text(tmp_path, _v1_config(tmp_path, 7, {}))
