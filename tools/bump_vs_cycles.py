"""A base-color image linked to the displacement (BlenderProc's ``set_displacement_from_principled_shader_value``,
v1's ``cf_color_link_to_displacement``): hybridgen's bumped shading against Cycles' bumped normals in Blender 4.2.

    .venv/bin/python tools/bump_vs_cycles.py [--factor 0.3] [--store tests/render/data/bump_cycles.json]

The scene (both engines): a 4 x 3 m plane in z = 0 (UVs 0..1, u along +x, v along +y) seen from 10 m straight above
at 128 x 96 pixels (3.125 cm each, a quarter texel), its base color the :func:`color_texture` image (32 x 24 texels,
sRGB; red, green and blue vary along different directions, so each channel's weight in the height shows) and its
displacement linked from that image times ``--factor`` m. Cycles renders through tools/bump_cycles.py in
``.venv-blenderproc``, where the real BlenderProc's call builds the node setup; its Normal pass at pixel centres is
the bumped normal (at 0.3 within 20 degrees of the plane's). Measured besides with throw-away bpy 4.2 scripts on
planes like this one: Cycles interpolates 8-bit sRGB texels before decoding them (an emission shader's pixels within
6e-7 of that), weighs the linear channels by Rec.709's luminance (fitted on a 1024 x 768 texture: 0.2121, 0.7150,
0.0718) and takes the height's differences one pixel footprint away along two diagonals of the surface
(:data:`FOOTPRINT_STEPS`), so texture detail finer than a pixel bumps less in Cycles than in hybridgen, whose bump
is the height's gradient at the point.

hybridgen renders the plane white-gray (Lambertian, albedo :data:`ALBEDO`) under a sun of irradiance :data:`SUN`
from :data:`TOWARDS_SUN` with direct light only: a pixel's radiance is ALBEDO / pi x SUN x (n . l), so it shows
the shading normal n along l. Printed: Cycles' tilt of the normal, and hybridgen's radiance over the radiance of
Cycles' normal per pixel (median and the largest deviation), for the height hybridgen reads now (the color's
linear luminance, ``displacement_from_color``) and before (the image's first channel as data). ``--orientation``
turns the whole scene so that the plane faces -y or +x (:data:`ORIENTATIONS`): Cycles dots the linked scalar with
the normal, so facing -y its bumps are inverted (hybridgen/render/pathtrace/linked_height.py). ``--store`` writes
a table of pixels (row, column, Cycles' normal) that tests/render/test_bump_from_color.py checks hybridgen
against (:func:`build_scene` rebuilds this scene there).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))
PLANE = (4.0, 3.0)  # m along x, y
TEXELS = (32, 24)  # width, height
RESOLUTION = (128, 96)
DISTANCE = 10.0  # m, camera height
ALBEDO, SUN = 0.5, 3.0  # hybridgen's plane: Lambertian albedo, sun irradiance (W m^-2)
TOWARDS_SUN = (0.45, 0.35, 0.82)
STORED_PIXELS = 160
ORIENTATIONS = {"up": np.eye(3),
                "minus_y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
                "plus_x": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]])}
"""Rotations (world from the plane's frame) of the whole scene - plane, camera, sun - so that the plane faces +z,
-y or +x. Cycles dots a scalar linked to the displacement with the normal (hybridgen/render/pathtrace/
linked_height.py): facing -y the bump is inverted, facing +x it is the upward plane's."""
FOOTPRINT_STEPS = np.array([[1.0, -1.0], [1.0, 1.0]]) / np.sqrt(2.0)
"""Where Cycles 4.2 takes a bump's height differences, per unit of the pixel footprint (in x, y on the plane): one
footprint away along two diagonals of the surface, forward (fitted here on 64 x 48 pixels: rms 2e-4 in slope)."""


def color_texture() -> np.ndarray:
    """TEXELS[1] x TEXELS[0] x 3 uint8 sRGB image: red a sine along x (period 16 texels), green along y (12),
    blue along the diagonal (10), each 0.5 +- 0.3 in sRGB values."""
    y, x = np.mgrid[0:TEXELS[1], 0:TEXELS[0]].astype(np.float64)
    channels = (np.sin(2 * np.pi * x / 16), np.sin(2 * np.pi * y / 12), np.sin(2 * np.pi * (x + y) / 10))
    return np.rint((0.5 + 0.3 * np.stack(channels, -1)) * 255).astype(np.uint8)


def plane() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(vertices, triangles, normals, per-vertex UVs) of the plane."""
    hx, hy = PLANE[0] / 2, PLANE[1] / 2
    vertices = np.array([[-hx, -hy, 0.0], [hx, -hy, 0], [hx, hy, 0], [-hx, hy, 0]])
    uvs = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    return vertices, np.array([[0, 1, 2], [0, 2, 3]]), np.tile([0.0, 0.0, 1.0], (4, 1)), uvs


def build_scene(factor: float, from_color: bool = True, orientation: str = "up") -> Any:
    """hybridgen's plane with :func:`color_texture` as displacement (``from_color``: read as Blender reads a linked
    color; else its first channel as data), its sun and its camera (pixel centres as in Cycles' render), all
    turned by :data:`ORIENTATIONS` ``[orientation]``."""
    import hybridgen as hg

    turn = np.eye(4)
    turn[:3, :3] = ORIENTATIONS[orientation]
    vertices, faces, _, uvs = plane()
    vertices = vertices @ turn[:3, :3].T
    material = hg.Material(name="bumped", base_color=(ALBEDO, ALBEDO, ALBEDO, 1.0), specular=0.0,
                           displacement_texture=color_texture(), displacement_scale=factor,
                           displacement_from_color=from_color)
    scene = hg.Scene()
    scene.add(hg.MeshObject(name="plane", vertices=vertices, faces=faces, uvs=uvs, material=material))
    scene.world.strength = 0.0
    z = np.asarray(TOWARDS_SUN, float) / np.linalg.norm(TOWARDS_SUN)
    x = np.cross([0.0, 1.0, 0.3], z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)  # a SUN shines along its -z
    scene.add_light(hg.Light("sun", "SUN", energy=SUN, local2world=turn @ pose))
    width, height = RESOLUTION
    f = width * DISTANCE / PLANE[0]
    scene.camera.intrinsics = hg.Intrinsics(np.array([[f, 0, (width - 1) / 2], [0, f, (height - 1) / 2], [0, 0, 1]]),
                                            width, height, clip_start=0.01)
    scene.camera.add_keypoint(turn @ np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, DISTANCE], [0, 0, 0, 1]]))
    return scene


def render_hybridgen(scene: Any, samples: int = 16) -> np.ndarray:
    """hybridgen's linear radiance (H x W x 3), direct light only."""
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

    view = PathTraceView(scene, PathTraceSettings(samples=samples, max_bounces=0), variant=choose_variant())
    return np.asarray(view.render(scene.camera.keypoints[0], seed=1), np.float64)


def lambert(normals: np.ndarray, orientation: str = "up") -> np.ndarray:
    """Radiance of the Lambertian plane under the sun at shading normals ``normals`` (... x 3, world axes of the
    scene turned to ``orientation``)."""
    light = ORIENTATIONS[orientation] @ (np.asarray(TOWARDS_SUN, float) / np.linalg.norm(TOWARDS_SUN))
    return ALBEDO / math.pi * SUN * np.maximum(normals @ light, 0.0)


def render_cycles(factor: float, work: Path, orientation: str = "up") -> dict[str, np.ndarray]:
    """Cycles' Normal and UV passes (H x W x 3 / x 2 float; normals in world axes) of the plane turned to
    ``orientation`` (tools/bump_cycles.py)."""
    from PIL import Image

    from blender_side import exr_passes, run_blender_side

    turn = np.eye(4)
    turn[:3, :3] = ORIENTATIONS[orientation]
    vertices, faces, normals, uvs = plane()
    np.savez(work / "scene.npz", **{"plane.vertices": vertices @ turn[:3, :3].T, "plane.faces": faces,
                                     "plane.normals": normals @ turn[:3, :3].T, "plane.uvs": uvs})
    Image.fromarray(color_texture()).save(work / "texture.png")
    matrix = turn @ np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, DISTANCE], [0, 0, 0, 1]])  # looks along -z
    spec = {"texture": str(work / "texture.png"), "factor": factor, "resolution": list(RESOLUTION),
            "camera": {"matrix_world": matrix.tolist(), "lens": 36.0 * DISTANCE / PLANE[0]}}
    (work / "spec.json").write_text(json.dumps(spec))
    run_blender_side("bump_cycles.py", [str(work / "scene.npz"), str(work / "spec.json"), str(work / "out.exr")],
                     work)
    return exr_passes(work / "out.exr")


def one_cell(uvs: np.ndarray) -> np.ndarray:
    """Pixels (H x W bool) whose UV and the points Cycles' bump differences reach (:data:`FOOTPRINT_STEPS`) lie in
    one cell between four texel centres: there that difference is the height's gradient, hybridgen's bump, up to
    the curvature of the sRGB decoding. Pixels at least one pixel inside the frame."""
    footprint = PLANE[0] / RESOLUTION[0]
    cells = []
    for step in (np.zeros(2), *FOOTPRINT_STEPS * footprint):
        u, v = uvs[..., 0] + step[0] / PLANE[0], uvs[..., 1] + step[1] / PLANE[1]
        cells.append((np.floor(u * TEXELS[0] - 0.5), np.floor((1.0 - v) * TEXELS[1] - 0.5)))
    same = np.all([(cx == cells[0][0]) & (cy == cells[0][1]) for cx, cy in cells[1:]], axis=0)
    same[[0, -1], :] = same[:, [0, -1]] = False
    return same


def stored_pixels(normals: np.ndarray, uvs: np.ndarray) -> list[list[float]]:
    """:data:`STORED_PIXELS` of the :func:`one_cell` pixels, evenly spread: [row, column, nx, ny, nz]."""
    rows, columns = np.nonzero(one_cell(uvs))
    chosen = np.linspace(0, rows.size - 1, STORED_PIXELS).round().astype(int)
    return [[int(rows[i]), int(columns[i]), *(round(float(c), 6) for c in normals[rows[i], columns[i]])]
            for i in chosen]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--factor", type=float, default=0.3, help="BlenderProc's multiply_factor (m)")
    parser.add_argument("--orientation", choices=sorted(ORIENTATIONS), default="up",
                        help="the way the plane faces (the scene turned by ORIENTATIONS)")
    parser.add_argument("--store", type=Path, default=None, help="write Cycles' normals at sampled pixels")
    ns = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bump-") as temp:
        cycles = render_cycles(ns.factor, Path(temp), ns.orientation)
    normals = cycles["Normal"]
    inside = np.zeros(normals.shape[:2], bool)
    inside[1:-1, 1:-1] = True
    cell = one_cell(cycles["UV"])
    facing = normals @ ORIENTATIONS[ns.orientation][:, 2]
    tilt = np.degrees(np.arccos(np.clip(facing[inside], -1.0, 1.0)))
    print(f"Cycles' bumped normals: tilt median {np.median(tilt):.2f} deg, max {tilt.max():.2f} deg "
          f"({inside.sum()} pixels, {cell.sum()} with their bump differences in one texel cell)")
    expected = lambert(normals, ns.orientation)
    for label, from_color in (("now (linear luminance)", True), ("before (first channel)", False)):
        ratio = render_hybridgen(build_scene(ns.factor, from_color, ns.orientation)).mean(-1) / expected
        print(f"hybridgen {label:24s} radiance / Cycles' normal's: median {np.median(ratio[inside]):.4f}, "
              f"max |ratio - 1| {np.abs(ratio[inside] - 1).max():.4f}; one-cell pixels "
              f"{np.abs(ratio[cell] - 1).max():.4f}")
    if ns.store:
        table = {"factor": ns.factor, "resolution": list(RESOLUTION), "orientation": ns.orientation,
                 "pixels": stored_pixels(normals, cycles["UV"])}
        rows = ",\n  ".join(json.dumps(pixel) for pixel in table.pop("pixels"))
        ns.store.write_text(json.dumps(table)[:-1] + f', "pixels": [\n  {rows}\n]}}\n')
        print(f"stored {ns.store}")


if __name__ == "__main__":
    main()
