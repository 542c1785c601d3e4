"""Color rendering: hybridgen vs a bare Mitsuba script on the same scene, and vs Blender Cycles.

Run: .venv/bin/python tools/bench_color.py [--res 640x480] [--spp 64] [--bounces 6] [--cycles] [--quick]

(a) hybridgen's per-keypoint color time over 8 keypoints (render_color into memory, sRGB encoding
    included) against a bare Mitsuba script that loads the same scene dictionary once, uses Mitsuba's own
    perspective sensor, and renders the same poses by moving the sensor through mi.traverse. The two
    alternate keypoint by keypoint; the first keypoint (kernel compilation) is reported separately.
(b) with --cycles: Blender Cycles on the CPU (bpy from PyPI, in its own .venv-bpy, created on first use),
    same geometry, resolution, spp and bounces (Cycles max_bounces b == Mitsuba max_depth b + 2), 2 threads.
"""
from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
REPO = Path(__file__).resolve().parents[1]


def bench_scene(width: int, height: int, keypoints: int) -> "hg.Scene":  # noqa: F821
    """A room (floor, walls, emissive ceiling) with 20 objects and an 82k-triangle smooth mesh."""
    import trimesh

    import hybridgen as hg

    rng = np.random.default_rng(3)
    scene = hg.Scene()
    walls = (("floor", [0, 0, 0], [0, 0, 0]), ("north", [0, 3, 1.5], [math.pi / 2, 0, 0]),
             ("south", [0, -3, 1.5], [-math.pi / 2, 0, 0]),
             ("east", [3, 0, 1.5], [0, -math.pi / 2, 0]), ("west", [-3, 0, 1.5], [0, math.pi / 2, 0]))
    for name, location, rotation in walls:
        wall = hg.make_primitive("plane", 6.0, name=name, category_id=1, color=(0.7, 0.7, 0.65),
                                 local2world=hg.object_pose(location, rotation))
        wall.material.specular = 0.0
        scene.add(wall)
    ceiling = hg.make_primitive("plane", 6.0, name="ceiling", category_id=2,
                                local2world=hg.object_pose([0, 0, 3], [math.pi, 0, 0]))
    ceiling.material.emission, ceiling.material.emission_strength, ceiling.material.specular = (1, 1, 1), 1.0, 0.0
    scene.add(ceiling)
    shapes = ["sphere", "cube", "cylinder", "cone", "torus"]
    for i in range(20):
        obj = hg.make_primitive(shapes[i % 5], 0.4, name=f"o{i}", category_id=3,
                                color=tuple(rng.uniform(0.1, 0.9, 3)),
                                local2world=hg.object_pose([*rng.uniform(-2.3, 2.3, 2), 0.2],
                                                           [0, 0, rng.uniform(0, 6)]))
        obj.material.specular, obj.material.roughness = 0.5, 0.4
        scene.add(obj)
    dense = trimesh.creation.icosphere(subdivisions=6, radius=0.6)
    scene.add(hg.MeshObject("dense", dense.vertices, dense.faces, vertex_normals=dense.vertices / 0.6,
                            category_id=4, local2world=hg.object_pose([0.3, 0.4, 0.6])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(math.radians(70), width, height, clip_start=0.05)
    for i in range(keypoints):
        angle = 2 * math.pi * i / keypoints
        scene.camera.add_keypoint(hg.look_at([2.4 * math.cos(angle), 2.4 * math.sin(angle), 1.6], [0, 0, 0.5]))
    return scene


def compare_with_bare_mitsuba(scene, spp: int, bounces: int) -> dict:  # type: ignore[no-untyped-def]
    import mitsuba as mi

    from hybridgen.render.mitsuba_scene import scene_dict
    from hybridgen.render.path_trace import OPENCV_TO_MITSUBA, PathTraceSettings
    from hybridgen.render.render_color import ColorProducer

    settings = PathTraceSettings(samples=spp, max_bounces=bounces)
    producer = ColorProducer(scene, settings, seed=1)  # loads the Mitsuba scene (timed below with the rest)
    intr = scene.camera.intrinsics
    bare = scene_dict(scene)
    bare["integrator"] = settings.integrator()
    fov = math.degrees(2 * math.atan(intr.width / (2 * intr.K[0, 0])))
    bare["sensor"] = {"type": "perspective", "fov_axis": "x", "fov": fov, "near_clip": intr.clip_start,
                      "far_clip": intr.clip_end, "film": {"type": "hdrfilm", "width": intr.width,
                                                          "height": intr.height, "rfilter": {"type": "box"}}}
    start = time.perf_counter()
    bare_scene = mi.load_dict(bare)
    bare_load = time.perf_counter() - start
    params = mi.traverse(bare_scene.sensors()[0])
    ours, theirs = [], []
    for index, pose in enumerate(scene.camera.keypoints):
        start = time.perf_counter()
        params["to_world"] = mi.ScalarTransform4f((pose @ OPENCV_TO_MITSUBA).tolist())
        params.update()
        np.array(mi.render(bare_scene, spp=spp, seed=index))
        theirs.append(time.perf_counter() - start)
        start = time.perf_counter()
        producer.produce(index, pose)  # render, linear -> sRGB uint8
        ours.append(time.perf_counter() - start)
    return {"ours": ours, "bare": theirs, "bare_load": bare_load, "variant": producer.view.variant}


def export_for_cycles(scene, path: Path, spp: int, bounces: int) -> None:  # type: ignore[no-untyped-def]
    arrays = {}
    objects = []
    for i, obj in enumerate(scene.objects):
        arrays[f"v{i}"] = obj.world_vertices()
        arrays[f"f{i}"] = obj.faces
        objects.append({"name": obj.name, "smooth": obj.vertex_normals is not None,
                        "color": list(obj.material.base_color), "roughness": obj.material.roughness,
                        "emission": obj.material.emission_strength})
    intr = scene.camera.intrinsics
    meta = {"objects": objects, "world": list(np.asarray(scene.world.color) * scene.world.strength),
            "resolution": [intr.width, intr.height], "K": intr.K.tolist(), "clip": [intr.clip_start, intr.clip_end],
            "spp": spp, "max_bounces": bounces, "min_bounces": 1, "threads": 2, "output": str(path.parent / "c.png")}
    np.savez(path, meta=json.dumps(meta), poses=np.stack(scene.camera.keypoints), **arrays)


def cycles_times(scene, spp: int, bounces: int) -> dict | None:  # type: ignore[no-untyped-def]
    venv = REPO / ".venv-bpy"
    python = venv / "bin" / "python"
    if not python.exists():
        print("creating .venv-bpy with bpy and numpy < 2 (one-off, several hundred MB) ...", flush=True)
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        done = subprocess.run([str(python), "-m", "pip", "install", "-q", "bpy", "numpy<2"], capture_output=True,
                              text=True)
        if done.returncode != 0:
            print(f"bpy could not be installed: {done.stderr.strip().splitlines()[-1:]}")
            return None
        print(f"  installed in {time.perf_counter() - start:.0f} s", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.npz"
        export_for_cycles(scene, path, spp, bounces)
        done = subprocess.run([str(python), str(REPO / "tools/cycles_render.py"), str(path)], capture_output=True,
                              text=True)
    if done.returncode != 0:
        print("Cycles failed:", done.stderr.strip()[-800:])
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="640x480")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--bounces", type=int, default=6, help="max_bounces (Cycles' meaning)")
    parser.add_argument("--keypoints", type=int, default=8)
    parser.add_argument("--cycles", action="store_true", help="also time Blender Cycles (installs bpy once)")
    parser.add_argument("--quick", action="store_true", help="160x120, 8 spp, 4 keypoints")
    args = parser.parse_args()
    if args.quick:
        args.res, args.spp, args.keypoints = "160x120", 8, 4
    width, height = (int(v) for v in args.res.split("x"))
    scene = bench_scene(width, height, args.keypoints)
    print(f"scene: {len(scene.objects)} objects, {scene.triangle_count:,} triangles, {width}x{height}, "
          f"{args.spp} spp, max_bounces {args.bounces}, {args.keypoints} keypoints")
    result = compare_with_bare_mitsuba(scene, args.spp, args.bounces)
    ours, bare = result["ours"], result["bare"]
    print(f"Mitsuba variant {result['variant']}")
    print(f"first keypoint (kernel compile): hybridgen {ours[0]:.2f} s, bare Mitsuba {bare[0]:.2f} s")
    steady_ours, steady_bare = statistics.median(ours[1:]), statistics.median(bare[1:])
    print(f"steady keypoint (median): hybridgen {steady_ours:.3f} s, bare Mitsuba {steady_bare:.3f} s, "
          f"ratio {steady_ours / steady_bare:.3f}")
    print(f"all {len(ours)} keypoints: hybridgen {sum(ours):.2f} s, bare {sum(bare):.2f} s, "
          f"overhead {100 * (sum(ours) / sum(bare) - 1):+.1f} %")
    if args.cycles:
        cycles = cycles_times(scene, args.spp, args.bounces)
        if cycles:
            steady_cycles = statistics.median(cycles["seconds"][1:])
            print(f"Blender Cycles {cycles['blender']} (CPU, 2 threads): first {cycles['seconds'][0]:.2f} s, steady "
                  f"{steady_cycles:.3f} s; hybridgen / Cycles = {steady_ours / steady_cycles:.2f}")


if __name__ == "__main__":
    main()
