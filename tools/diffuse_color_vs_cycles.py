"""hybridgen's diffuse-color pass (``diffuse_color``; bproc's ``diffuse`` output) against Cycles' Diffuse Color
pass (DiffCol) in Blender 4.2, pixel by pixel.

    .venv/bin/python tools/diffuse_color_vs_cycles.py [--res 400x320] [--store tests/render/data/diffuse_color_cycles.json]

The scene (both engines, the same triangles and smooth normals): 20 of Blender's UV spheres (64 x 32, r 0.45 m) in a 5 x 4
grid seen from 9 m, each with a Principled BSDF of one sweep entry (:data:`MATERIALS`: Blender's input names,
over an orange base): roughness, IOR, Specular IOR Level, metallic, transmission, coat (plain and tinted), sheen,
specular tint, subsurface, a white base. Cycles renders through tools/diffuse_color_cycles.py in
``.venv-blenderproc`` at one sample per pixel through a 0.01-pixel box filter - DiffCol at each pixel centre,
where hybridgen's raster passes sample too (DiffCol is no estimate: one sample is exact).

Printed per sphere, over the pixels well inside it (an analytic ray cast): Cycles' mean DiffCol (R, G, B), then
hybridgen's over Cycles', mean of R, G, B, before (the ``albedo`` pass: the base color, what bproc's ``diffuse``
was) and after (the ``diffuse_color`` pass; where Cycles' DiffCol is 0, hybridgen's mean marked ``*``), and
after's largest per-pixel difference; then the ratio after at view cosines near 1, 0.5 and 0.2. ``--store`` writes, per sphere, its Blender inputs and six pixels (row, column,
view cosine, Cycles' RGB) at view cosines from 1 to 0.17 - the table tests/render/test_diffuse_color.py checks
the pass against (:func:`build_scene` rebuilds this scene there).
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
BASE = [0.8, 0.45, 0.2]
MATERIALS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("dielectric", {}), ("rough_0.1", {"Roughness": 0.1}), ("rough_0.9", {"Roughness": 0.9}),
    ("rough_0", {"Roughness": 0.0}), ("ior_1.2", {"IOR": 1.2}), ("ior_2", {"IOR": 2.0}),
    ("level_0", {"Specular IOR Level": 0.0}), ("level_0.25", {"Specular IOR Level": 0.25}),
    ("level_1", {"Specular IOR Level": 1.0}), ("metallic_0.5", {"Metallic": 0.5}), ("metal", {"Metallic": 1.0}),
    ("transmission_0.5", {"Transmission Weight": 0.5}), ("glass", {"Transmission Weight": 1.0}),
    ("coat", {"Coat Weight": 1.0}), ("coat_tint", {"Coat Weight": 1.0, "Coat Tint": [0.9, 0.5, 0.3]}),
    ("sheen", {"Sheen Weight": 1.0}), ("specular_tint", {"Specular Tint": [0.5, 1.0, 0.3]}),
    ("subsurface_0.5", {"Subsurface Weight": 0.5}), ("white", {"Base Color": [1.0, 1.0, 1.0]}),
    ("ior_1.45_rough_0.3", {"IOR": 1.45, "Roughness": 0.3}),
)
"""Sweep entries: name, Principled BSDF inputs (Blender's names) over Base Color :data:`BASE`, Blender's defaults
otherwise (Roughness 0.5, IOR 1.5, Specular IOR Level 0.5)."""
COLUMNS, RADIUS, SPACING, DISTANCE, HALF_WIDTH = 5, 0.45, 1.0, 9.0, 2.8
SEGMENTS, RINGS = 64, 32
TARGET_COSINES = (1.0, 0.8, 0.6, 0.4, 0.25, 0.17)
FIELDS = {"Base Color": "base_color", "Roughness": "roughness", "Metallic": "metallic",
          "Specular IOR Level": "specular", "IOR": "ior", "Transmission Weight": "transmission"}


def sphere(centre: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices, triangles, unit normals) of Blender's UV sphere (:data:`SEGMENTS` x :data:`RINGS`, radius
    :data:`RADIUS`) at ``centre``, smooth."""
    from hybridgen.scene.blender_primitives import uv_sphere

    mesh = uv_sphere(SEGMENTS, RINGS, RADIUS)
    triangles, _ = mesh.fan_triangles()
    return mesh.positions + centre, mesh.corners[triangles], mesh.positions / RADIUS


def centres() -> list[np.ndarray]:
    """Each sweep entry's sphere centre (m), row by row from the top left as the camera sees them."""
    rows = math.ceil(len(MATERIALS) / COLUMNS)
    return [np.array([(i % COLUMNS - (COLUMNS - 1) / 2) * SPACING, 0.0, ((rows - 1) / 2 - i // COLUMNS) * SPACING])
            for i in range(len(MATERIALS))]


def material(name: str, inputs: dict[str, Any]) -> Any:
    """The hybridgen material of Blender inputs over :data:`BASE` (other inputs in ``extra``)."""
    import hybridgen as hg
    from hybridgen.scene.principled_inputs import BY_BLENDER_NAME

    values: dict[str, Any] = {"base_color": (*BASE, 1.0)}
    extra: dict[str, Any] = {}
    for key, value in inputs.items():
        if key in FIELDS:
            values[FIELDS[key]] = (*value, 1.0) if key == "Base Color" else value
        else:
            entry = BY_BLENDER_NAME[key]
            extra[entry.key] = tuple(value) if entry.kind == "color" else value
    return hg.Material(name=name, **values, extra=extra)


def build_scene(width: int, height: int) -> Any:
    """The sweep's spheres and camera in hybridgen (no lights: the passes do not need them)."""
    import hybridgen as hg

    scene = hg.Scene()
    for (name, inputs), centre in zip(MATERIALS, centres()):
        vertices, faces, normals = sphere(centre)
        scene.add(hg.MeshObject(name=name, vertices=vertices, faces=faces, vertex_normals=normals,
                                material=material(name, inputs)))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(2 * math.atan(HALF_WIDTH / DISTANCE), width, height,
                                                     clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.0, -DISTANCE, 0.0], [0.0, 0.0, 0.0]))
    return scene


def render_cycles(scene: Any, work: Path) -> dict[str, np.ndarray]:
    """Cycles' DiffCol and Normal passes (H x W x 3 float) of the sweep (tools/diffuse_color_cycles.py)."""
    from blender_side import exr_passes, run_blender_side

    arrays: dict[str, np.ndarray] = {}
    for (name, _), centre in zip(MATERIALS, centres()):
        vertices, faces, normals = sphere(centre)
        arrays.update({f"{name}.vertices": vertices, f"{name}.faces": faces, f"{name}.normals": normals})
    np.savez(work / "scene.npz", **arrays)
    intr = scene.camera.intrinsics
    spec = {"resolution": [intr.width, intr.height],
            "objects": [{"name": name, "inputs": {"Base Color": BASE, **inputs}} for name, inputs in MATERIALS],
            "camera": {"matrix_world": (scene.camera.keypoints[0] @ np.diag([1.0, -1, -1, 1])).tolist(),
                       "lens": float(intr.K[0, 0] * 36.0 / intr.width)}}
    (work / "spec.json").write_text(json.dumps(spec))
    run_blender_side("diffuse_color_cycles.py", [str(work / "scene.npz"), str(work / "spec.json"),
                                                 str(work / "out.exr")], work)
    return exr_passes(work / "out.exr")


def pixel_rays(scene: Any) -> tuple[np.ndarray, np.ndarray]:
    """(camera origin, unit world direction of each pixel centre's ray (H x W x 3))."""
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], -1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    return pose[:3, 3], rays / np.linalg.norm(rays, axis=-1, keepdims=True)


def sphere_masks(scene: Any, margin: float = 0.985) -> dict[str, np.ndarray]:
    """Per sphere, the pixels whose centre ray passes within ``margin`` x the radius of its centre (the
    tessellated sphere's edges lie beyond 0.9988 of it)."""
    origin, rays = pixel_rays(scene)
    masks = {}
    for (name, _), centre in zip(MATERIALS, centres()):
        oc = origin - centre
        b = rays @ oc
        masks[name] = oc @ oc - b * b < (margin * RADIUS) ** 2
    return masks


def view_cosines(scene: Any, normals: np.ndarray) -> np.ndarray:
    """|cos| between each pixel's shading normal (Cycles' Normal pass, world) and its ray."""
    return np.abs((normals * pixel_rays(scene)[1]).sum(-1))


def samples(mask: np.ndarray, cosines: np.ndarray, diffcol: np.ndarray) -> list[list[float]]:
    """Pixels of ``mask`` nearest to each of :data:`TARGET_COSINES`: [row, column, cosine, R, G, B]."""
    rows, columns = np.nonzero(mask)
    chosen = []
    for target in TARGET_COSINES:
        best = int(np.argmin(np.abs(cosines[rows, columns] - target)))
        r, c = int(rows[best]), int(columns[best])
        chosen.append([r, c, round(float(cosines[r, c]), 6), *(round(float(x), 7) for x in diffcol[r, c])])
    return chosen


def main() -> None:
    import hybridgen as hg
    from hybridgen.render.raster.albedo_pass import AlbedoPass

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--res", default="400x320")
    parser.add_argument("--store", type=Path, default=None, help="write the sampled Cycles pixels as a test table")
    ns = parser.parse_args()
    width, height = (int(v) for v in ns.res.split("x"))
    scene = build_scene(width, height)
    with tempfile.TemporaryDirectory(prefix="diffcol-") as temp:
        cycles = render_cycles(scene, Path(temp))
    view = hg.RasterView(scene)
    pose = scene.camera.keypoints[0]
    before = AlbedoPass(view).render(pose, background=(0.0, 0.0, 0.0))
    after = AlbedoPass(view, diffuse_color=True).render(pose, background=(0.0, 0.0, 0.0))
    diffcol, cosines = cycles["DiffCol"], view_cosines(scene, cycles["Normal"])
    background = ~np.any(list(sphere_masks(scene, 1.01).values()), axis=0)
    print(f"background: Cycles' DiffCol max {diffcol[background].max():.3g}, hybridgen's {after[background].max():.3g}")
    print(f"{'sphere':20s} {'Cycles mean DiffCol':>24s}  before  after  max|after - Cycles|  after at cos ~1 / 0.5 / 0.2")
    table: dict[str, Any] = {"res": [width, height], "base": BASE, "objects": {}}
    for (name, inputs), (_, mask) in zip(MATERIALS, sphere_masks(scene).items()):
        theirs = diffcol[mask].mean(0)
        ratio = (lambda image: f"{image[mask].mean() / theirs.mean():6.3f}" if theirs.mean() > 0 else
                 f"{image[mask].mean():6.3f}*")  # * Cycles' DiffCol is 0: hybridgen's mean itself
        by_angle = []
        for low, high in ((0.95, 1.01), (0.45, 0.55), (0.15, 0.25)):
            band = mask & (cosines >= low) & (cosines < high)
            by_angle.append(after[band].mean() / max(diffcol[band].mean(), 1e-12))
        print(f"{name:20s} {' '.join(f'{c:7.4f}' for c in theirs)}  {ratio(before)} {ratio(after)}  "
              f"{np.abs(after[mask] - diffcol[mask]).max():10.2e}        "
              f"{' / '.join(f'{r:.4f}' for r in by_angle)}   ({mask.sum()} px)")
        table["objects"][name] = {"inputs": inputs, "samples": samples(mask, cosines, diffcol)}
    if ns.store:
        ns.store.write_text(json.dumps(table, indent=1) + "\n")
        print(f"stored {ns.store}")


if __name__ == "__main__":
    main()
