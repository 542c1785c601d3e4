"""Real-asset scenes: load, first keypoint and steady keypoint time and peak memory of a generated 3D-FRONT-like
house, with and without instancing (shared geometry: one GPU upload and one Mitsuba shape group per model).

Run: .venv/bin/python tools/bench_assets.py [--res 640x480] [--spp 4] [--placements 100] [--models 10]
     [--sets 20] [--triangles 20000]

The house (written to a temporary folder in the published layouts): a 12 x 10 m floor, four walls and a
ceiling as 3D-FRONT ``mesh`` arrays, ``--models`` 3D-FUTURE models (``raw_model.obj`` spheres of about
``--triangles`` triangles each, with ``texture.png``) placed ``--placements`` times over two rooms, and
``--sets`` ambientCG texture sets (256 px color, roughness, normal, displacement maps) loaded with
loader.CCMaterialLoader; every model gets one set for all its placements, walls and floor get their own.
Each mode runs in its own process with its own empty mesh cache (peak RSS is per process): config modules up to the scene (load), then a
path-traced color keypoint plus depth/normals/segmentation labels (first keypoint, JIT compilation included),
then the mean of three more keypoints (steady). Times are wall-clock on a possibly shared machine: compare
the two modes of the same run.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from harness import Stopwatch, rss_mib

REPO = Path(__file__).resolve().parents[1]


def _sphere_obj(path: Path, triangles: int, radius: float) -> None:
    """A UV sphere OBJ (y up, resting on y = 0) of about ``triangles`` triangles."""
    rings = max(4, int(math.sqrt(triangles / 2)))
    segments = 2 * rings
    lines = []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            x, y, z = math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)
            lines.append(f"v {radius * x:.5f} {radius * (y + 1):.5f} {radius * z:.5f}")
            lines.append(f"vt {j / segments:.5f} {1 - i / rings:.5f}")
    row = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = i * row + j + 1, i * row + j + 2, (i + 1) * row + j + 2, (i + 1) * row + j + 1
            lines.append(f"f {a}/{a} {d}/{d} {c}/{c}")
            lines.append(f"f {a}/{a} {c}/{c} {b}/{b}")
    path.write_text("\n".join(lines) + "\n")


def _quad(xyz: list[float], normal: list[float]) -> dict:
    return {"xyz": xyz, "normal": normal * 4, "uv": [0, 0, 4, 0, 4, 4, 0, 4], "faces": [0, 1, 2, 0, 2, 3]}


def make_house(root: Path, models: int, placements: int, sets: int, triangles: int) -> Path:
    """Writes the house, models, texture sets and a config; returns the config's path."""
    from PIL import Image

    rng = np.random.default_rng(5)
    future, cc = root / "3D-FUTURE-model", root / "cc"
    for m in range(models):
        folder = future / f"jid-{m:03d}"
        folder.mkdir(parents=True)
        _sphere_obj(folder / "raw_model.obj", triangles, 0.2 + 0.03 * m)
        Image.fromarray(rng.integers(0, 255, (64, 64, 3), dtype=np.uint8)).save(folder / "texture.png")
    for s in range(sets):
        asset = cc / f"Tiles{s:03d}"
        asset.mkdir(parents=True)
        for kind, channels in (("Color", 3), ("Roughness", 1), ("NormalGL", 3), ("Displacement", 1)):
            image = rng.integers(0, 255, (256, 256, channels), dtype=np.uint8)
            if kind == "NormalGL":
                image[..., 2] = 255
            Image.fromarray(image.squeeze()).save(asset / f"Tiles{s:03d}_2K_{kind}.jpg")
    (root / "textures").mkdir()
    (root / "mapping.csv").write_text("id,name\n0,void\n1,floor\n2,wallinner\n3,ceiling\n4,chair\n")
    w, d, h = 12.0, 10.0, 2.8
    meshes = [
        {"uid": "floor", "type": "Floor", "material": "m0", **_quad([0, 0, 0, w, 0, 0, w, 0, d, 0, 0, d], [0, 1, 0])},
        {"uid": "ceiling", "type": "Ceiling", "material": "m1",
         **_quad([0, h, 0, 0, h, d, w, h, d, w, h, 0], [0, -1, 0])},
    ]
    for i, (a, b) in enumerate([((0, 0), (w, 0)), ((w, 0), (w, d)), ((w, d), (0, d)), ((0, d), (0, 0))]):
        xyz = [a[0], 0, a[1], b[0], 0, b[1], b[0], h, b[1], a[0], h, a[1]]
        meshes.append({"uid": f"wall{i}", "type": "WallInner", "material": "m0", **_quad(xyz, [0, 0, 1])})
    children = [[], []]
    for p in range(placements):
        room = p % 2
        children[room].append({"ref": f"f{p % models}", "instanceid": f"furniture/{p}",
                               "pos": [float(rng.uniform(0.5, w - 0.5)), 0.0, float(rng.uniform(0.5, d - 0.5))],
                               "rot": [0, float(rng.uniform(-1, 1)), 0, 1], "scale": [1, 1, 1]})
    house = {"material": [{"uid": "m0", "texture": "", "normaltexture": "", "color": [200, 190, 180, 255]},
                          {"uid": "m1", "texture": "", "normaltexture": "", "color": [250, 250, 250, 255]}],
             "mesh": meshes,
             "furniture": [{"uid": f"f{m}", "jid": f"jid-{m:03d}", "category": "chair"} for m in range(models)],
             "scene": {"room": [{"instanceid": f"Room-{r}", "children": c} for r, c in enumerate(children)]}}
    (root / "house.json").write_text(json.dumps(house))
    config = {"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(root / "out")}, "seed": 1}},
        {"module": "loader.Front3DLoader", "config": {
            "json_path": str(root / "house.json"), "3D_future_model_path": str(future),
            "3D_front_texture_path": str(root / "textures"), "mapping_file": str(root / "mapping.csv"),
            "ceiling_light_strength": 2.0}},
        {"module": "loader.CCMaterialLoader", "config": {"folder_path": str(cc)}},
    ]}
    path = root / "config.json"
    path.write_text(json.dumps(config))
    return path


def run_mode(config: Path, shared: bool, width: int, height: int, spp: int) -> dict:
    """One measurement in this process (see the module doc)."""
    import hybridgen as hg
    from hybridgen.config.config_file import load_config
    from hybridgen.modules.material_library import material_library
    from hybridgen.render import shared_geometry
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.run.pipeline import build_modules, execute

    shared_geometry.ENABLED = shared
    watch = Stopwatch()
    loaded = load_config(config, [])
    context = execute(loaded, build_modules(loaded))
    scene = context.scene
    library = [entry.material for entry in material_library(context)]
    by_uid: dict[str, object] = {}
    for index, obj in enumerate(scene.objects):  # one set per model (all its placements), walls/floor their own
        key = obj.attributes.get("uid") or obj.name
        if key not in by_uid:
            by_uid[key] = library[len(by_uid) % len(library)]
        if obj.material.emission_strength == 0:
            obj.material = by_uid[key]
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.2, width, height)
    poses = [hg.look_at([1.0 + i, 1.0, 1.7], [6.0, 5.0, 0.5]) for i in range(4)]
    load_s = watch.read()[0]

    def keypoint(view: PathTraceView, raster: hg.RasterView, pose: np.ndarray, seed: int) -> None:
        view.render(pose, seed=seed)
        raster.render(pose, passes=("depth", "normals", "instance_segmaps"))

    watch = Stopwatch()
    view = PathTraceView(scene, PathTraceSettings(samples=spp, max_bounces=3), variant=choose_variant())
    raster = hg.RasterView(scene)
    keypoint(view, raster, poses[0], 0)
    first_s = watch.read()[0]
    watch = Stopwatch()
    for i, pose in enumerate(poses[1:], 1):
        keypoint(view, raster, pose, i)
    steady_s = watch.read()[0] / (len(poses) - 1)
    return {"shared": shared, "objects": len(scene.objects),
            "triangles": int(sum(len(o.faces) for o in scene.objects)),
            "gpu_uploads": len({id(g.positions) for g in raster.gpu_objects}),
            "load_s": round(load_s, 2), "first_keypoint_s": round(first_s, 2), "steady_keypoint_s": round(steady_s, 2),
            "peak_rss_mib": round(rss_mib()[1], 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--res", default="640x480")
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--placements", type=int, default=100)
    parser.add_argument("--models", type=int, default=10)
    parser.add_argument("--sets", type=int, default=20)
    parser.add_argument("--triangles", type=int, default=20000)
    parser.add_argument("--mode", choices=("shared", "separate"), help=argparse.SUPPRESS)
    parser.add_argument("--config", help=argparse.SUPPRESS)
    args = parser.parse_args()
    width, height = (int(v) for v in args.res.split("x"))
    if args.mode:
        print(json.dumps(run_mode(Path(args.config), args.mode == "shared", width, height, args.spp)))
        return
    with tempfile.TemporaryDirectory(prefix="bench_assets_") as folder:
        config = make_house(Path(folder), args.models, args.placements, args.sets, args.triangles)
        for mode in ("shared", "separate"):
            # a fresh mesh cache per mode: each parses every model file once
            env = {**os.environ, "HYBRIDGEN_CACHE_DIR": str(Path(folder) / f"cache-{mode}")}
            out = subprocess.run([sys.executable, __file__, "--mode", mode, "--config", str(config), "--res", args.res,
                                  "--spp", str(args.spp)], capture_output=True, text=True, cwd=REPO, check=False,
                                 env=env)
            if out.returncode != 0:
                print(out.stderr[-3000:], file=sys.stderr)
                raise SystemExit(f"{mode} run failed")
            print(out.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    main()
