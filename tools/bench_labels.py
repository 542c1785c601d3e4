"""Label throughput: hybridgen's raster pass vs pyrender, and end to end with HDF5 writing.

Run: .venv/bin/python tools/bench_labels.py [--frames 8] [--rounds 5] [--quick] [--breakdown]
Needs the ``bench`` extras (pyrender, pybullet for the real meshes, embreex for ``--check``).

Each engine lives in its own process (two OpenGL contexts in one process would fight over which is
current); the parent alternates them round by round (and which goes first), so machine noise hits both alike.
A round renders ``--frames`` orbit poses after an untimed warm-up; frames/s are medians over rounds.
Readback and turning the raw buffers into arrays are included on both sides:
  hybridgen: the real label path (two-deep submit/collect pipeline) making depth + normals + instance ids
             + class ids (+ the per-keypoint instance records), handed to no writer;
  pyrender:  one ``render(flags=SEG)`` per keypoint (colour-coded instance ids + depth), ids decoded.
``--check`` compares both engines' depth and ids at one pose with an Embree ray cast through pixel centres.
"""
from __future__ import annotations

import argparse
import importlib.util
import multiprocessing as mp
import os
import statistics
import sys
import tempfile
import time
import types
import zlib
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

CHECK_RESOLUTION = "640x480"


def _ours_worker(conn: Any) -> None:
    import bench_scenes as bs
    import numpy as np

    import hybridgen as hg
    from hybridgen.io import hdf5_single
    from hybridgen.render.keypoint_loop import run_keypoints
    from hybridgen.render.passes import PASSES
    from hybridgen.render.render_labels import LabelProducer

    request = hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"])
    views: dict[str, tuple[Any, Any]] = {}
    poses: dict[tuple[str, int], list[np.ndarray]] = {}
    warm: dict[str, str] = {}

    def prepare(name: str, resolution: str, frames: int) -> tuple[Any, Any, list[np.ndarray]]:
        if name not in views:
            scene = bs.ALL_SCENES[name]()
            views[name] = (scene, hg.RasterView(scene))
        scene, view = views[name]
        scene.camera.intrinsics = bs.intrinsics(*bs.RESOLUTIONS[resolution])
        if (name, frames) not in poses:
            poses[name, frames] = bs.orbit_poses(scene, frames)
        if warm.get(name) != resolution:  # untimed: framebuffers of this size in both pipeline slots
            warm[name] = resolution
            label_pass(scene, view, poses[name, frames][:2], [])
        return scene, view, poses[name, frames]

    def label_pass(scene: Any, view: Any, keypoints: list[np.ndarray], sinks: list[Any]) -> float:
        scene.camera.keypoints.clear()
        for pose in keypoints:
            scene.camera.add_keypoint(pose)
        start = time.perf_counter()
        run_keypoints(scene, sinks, [LabelProducer(scene, request, view=view)])
        elapsed = time.perf_counter() - start
        scene.camera.keypoints.clear()
        return elapsed

    while True:
        message = conn.recv()
        if message is None:
            return
        kind, name, resolution, frames, *options = message
        scene, view, keypoints = prepare(name, resolution, frames)
        if kind == "raw":
            conn.send(len(keypoints) / label_pass(scene, view, keypoints, []))
        elif kind == "hdf5":  # writer built, every keypoint written, file finalized: all timed
            compression = options[0]
            if compression == "gzip-isal":  # experiment: the writer's zlib.compress swapped for ISA-L's
                from isal import isal_zlib  # same zlib stream format, read by HDF5's gzip filter

                hdf5_single.zlib = types.SimpleNamespace(compress=isal_zlib.compress)
            try:
                with tempfile.TemporaryDirectory() as tmp:
                    path = Path(tmp) / "data.hdf5"
                    start = time.perf_counter()
                    writer = hg.Hdf5SingleFileWriter(path, compression=compression.split("-")[0])
                    label_pass(scene, view, keypoints, [writer])
                    writer.finalize({"object_states": [o.state() for o in scene.objects]})
                    elapsed = time.perf_counter() - start
                    conn.send((len(keypoints) / elapsed, path.stat().st_size / len(keypoints)))
            finally:
                hdf5_single.zlib = zlib
        elif kind == "frame":
            raw = view.render_raw(keypoints[0])
            conn.send((PASSES["depth"].compute(raw), raw.instance.astype(np.int32)))
        elif kind == "breakdown":  # serial, no pipelining: where one keypoint's time goes
            tables = request.tables(view)
            stages: dict[str, list[float]] = {"submit": [], "raster wait": [], "readback": [], "passes": []}
            for pose in keypoints:
                t0 = time.perf_counter()
                view.submit(pose, slot=0)  # uniforms + draw calls; llvmpipe shades vertices and bins here
                t1 = time.perf_counter()
                view.ctx.finish()  # llvmpipe's rasterizer threads finish the fragments
                t2 = time.perf_counter()
                raw = view.collect(0)
                t3 = time.perf_counter()
                request.compute(raw, tables)
                t4 = time.perf_counter()
                for key, value in zip(stages, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
                    stages[key].append(value)
            conn.send({key: 1000 * statistics.median(values) for key, values in stages.items()})


def _pyrender_worker(conn: Any) -> None:
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    import numpy as np

    if not hasattr(np, "infty"):
        np.infty = np.inf  # pyrender 0.1.45 still uses the alias removed in NumPy 2
    import bench_scenes as bs
    import pyrender
    import trimesh

    built: dict[str, dict[str, Any]] = {}
    flip = np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV camera axes -> OpenGL camera axes

    def prepare(name: str, resolution: str, frames: int) -> dict[str, Any]:
        if name not in built:
            ours = bs.ALL_SCENES[name]()
            scene = pyrender.Scene()
            seg = {}
            for obj in ours.objects:  # indexed meshes (smooth=True): pyrender's fastest path
                mesh = pyrender.Mesh.from_trimesh(trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False))
                seg[scene.add(mesh)] = [obj.instance_id % 256, obj.instance_id // 256, 0]
            built[name] = {"ours": ours, "scene": scene, "seg": seg, "poses": {}, "resolution": None,
                           "camera": scene.add(pyrender.IntrinsicsCamera(1.0, 1.0, 0.0, 0.0)),
                           "renderer": pyrender.OffscreenRenderer(640, 480)}
        b = built[name]
        if frames not in b["poses"]:
            b["poses"][frames] = [p @ flip for p in bs.orbit_poses(b["ours"], frames)]
        if b["resolution"] != resolution:  # same K (pixel centres: cx, cy + 0.5, see FACTS); untimed warm-up
            width, height = bs.RESOLUTIONS[resolution]
            intr = bs.intrinsics(width, height)
            K = intr.K
            b["camera"].camera = pyrender.IntrinsicsCamera(K[0, 0], K[1, 1], K[0, 2] + 0.5, K[1, 2] + 0.5,
                                                           znear=intr.clip_start, zfar=intr.clip_end)
            b["renderer"].viewport_width, b["renderer"].viewport_height = width, height
            render(b, b["poses"][frames][0])
            b["resolution"] = resolution
        return b

    def render(b: dict[str, Any], pose: np.ndarray) -> tuple[Any, Any]:
        b["scene"].set_pose(b["camera"], pose)
        color, depth = b["renderer"].render(b["scene"], flags=pyrender.RenderFlags.SEG, seg_node_map=b["seg"])
        return depth, color[..., 0].astype(np.int32) + 256 * color[..., 1].astype(np.int32)

    while True:
        message = conn.recv()
        if message is None:
            return
        kind, name, resolution, frames = message
        b = prepare(name, resolution, frames)
        keypoints = b["poses"][frames]
        if kind == "raw":
            start = time.perf_counter()
            for pose in keypoints:
                render(b, pose)
            conn.send(len(keypoints) / (time.perf_counter() - start))
        elif kind == "frame":
            conn.send(render(b, keypoints[0]))


def _raycast(scene: Any, pose: Any, intr: Any) -> tuple[Any, Any]:
    """Depth (inf: no hit) and instance ids through every pixel centre, with Embree through trimesh."""
    import numpy as np
    import trimesh

    world = trimesh.util.concatenate([trimesh.Trimesh(o.world_vertices(), o.faces, process=False)
                                      for o in scene.objects])
    owner = np.concatenate([np.full(len(o.faces), o.instance_id) for o in scene.objects])
    rays = intr.pixel_rays().reshape(-1, 3)
    directions = rays @ pose[:3, :3].T
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origins = np.broadcast_to(pose[:3, 3], directions.shape)
    locations, rows, faces = world.ray.intersects_location(origins, directions, multiple_hits=False)
    depth = np.full(len(rays), np.inf)
    ids = np.zeros(len(rays), np.int64)
    depth[rows] = (locations - pose[:3, 3]) @ pose[:3, 2]  # camera z (OpenCV: +z forward)
    ids[rows] = owner[faces]
    return depth.reshape(intr.height, intr.width), ids.reshape(intr.height, intr.width)


def _compare(depth: Any, ids: Any, ref_depth: Any, ref_ids: Any) -> str:
    import numpy as np

    hit, ref_hit = ids > 0, ref_ids > 0
    both = hit & ref_hit
    dz = np.abs(depth[both] - ref_depth[both])
    return (f"hit differs {100 * np.mean(hit != ref_hit):5.2f} %  id differs {100 * np.mean(ids[both] != ref_ids[both]):5.2f} %"
            f"  |dz| median {np.median(dz) * 1000:8.4f} mm  p99 {np.percentile(dz, 99) * 1000:8.2f} mm"
            f"  >1 cm {100 * np.mean(dz > 0.01):5.2f} %")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=8, help="orbit poses (keypoints) per round")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds per scene, resolution and engine")
    parser.add_argument("--quick", action="store_true", help="smoke check: 640x480 only, 4 frames, 2 rounds, gzip")
    parser.add_argument("--scenes", nargs="+", help="scene names (default: the three standard ones); "
                        "'1.3M icosphere' is an extra")
    parser.add_argument("--compression", nargs="+", choices=["gzip", "gzip-isal", "lzf", "none"],
                        help="HDF5 compressions to time end to end (default: gzip, gzip-isal if the isal package "
                        "is installed, lzf, none; --quick: gzip). gzip-isal is an experiment: hybridgen's writer "
                        "with zlib.compress swapped for isal_zlib.compress (same stream format)")
    parser.add_argument("--check", action=argparse.BooleanOptionalAction, default=None,
                        help="depth/id agreement of both engines with a ray cast (default: on unless --quick)")
    parser.add_argument("--breakdown", action="store_true", help="also time our stages serially per keypoint")
    parser.add_argument("--skip-pyrender", action="store_true", help="only the HDF5 end-to-end part")
    args = parser.parse_args()

    import bench_scenes as bs

    names = args.scenes or list(bs.SCENES)
    unknown = [n for n in names if n not in bs.ALL_SCENES]
    if unknown:
        parser.error(f"unknown scene(s) {unknown}; known: {list(bs.ALL_SCENES)}")
    resolutions = ["640x480"] if args.quick else list(bs.RESOLUTIONS)
    frames = 4 if args.quick else args.frames
    rounds = 2 if args.quick else args.rounds
    compressions = args.compression or (["gzip"] if args.quick else
                                        ["gzip", *(["gzip-isal"] if importlib.util.find_spec("isal") else []),
                                         "lzf", "none"])
    check = (not args.quick) if args.check is None else args.check

    spawn = mp.get_context("spawn")
    workers = {}
    for engine, target in (("ours", _ours_worker), ("pyrender", _pyrender_worker)):
        if engine == "pyrender" and args.skip_pyrender:
            continue
        parent, child = spawn.Pipe()
        process = spawn.Process(target=target, args=(child,), daemon=True)
        process.start()
        workers[engine] = (parent, process)

    def ask(engine: str, *message: Any) -> Any:
        conn, _ = workers[engine]
        conn.send(message)
        return conn.recv()

    triangles = {name: bs.ALL_SCENES[name]().triangle_count for name in names}
    print(f"{frames} keypoints per round, {rounds} rounds, median frames/s; ours = depth + normals + instance + class; "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f} (other processes skew absolute numbers)")
    if not args.skip_pyrender:
        print(f"\n{'scene':<20} {'resolution':<10} {'triangles':>10} {'ours fps':>9} {'pyrender fps':>13} "
              f"{'ours/pyrender':>14}")
        for name in names:
            for resolution in resolutions:
                fps: dict[str, list[float]] = {"ours": [], "pyrender": []}
                for r in range(rounds):
                    for engine in (("ours", "pyrender") if r % 2 == 0 else ("pyrender", "ours")):
                        fps[engine].append(ask(engine, "raw", name, resolution, frames))
                a, b = statistics.median(fps["ours"]), statistics.median(fps["pyrender"])
                print(f"{name:<20} {resolution:<10} {triangles[name]:>10,} {a:>9.1f} {b:>13.1f} {a / b:>14.2f}",
                      flush=True)

    if args.breakdown:
        print("\nours, serial (no pipelining), median ms per keypoint: submit = uniforms + draw calls (llvmpipe "
              "shades vertices and bins triangles on this thread), raster wait = glFinish, readback, passes (numpy)")
        for name in names:
            for resolution in resolutions:
                stages = ask("ours", "breakdown", name, resolution, frames)
                total = sum(stages.values())
                print(f"{name:<20} {resolution:<10} " + "  ".join(f"{k} {v:6.1f}" for k, v in stages.items())
                      + f"  total {total:6.1f} ms ({1000 / total:5.1f} fps serial)", flush=True)

    if check and not args.skip_pyrender:
        print(f"\nagreement at one pose, {CHECK_RESOLUTION}, against an Embree ray cast through pixel centres "
              "(|dz| over pixels both hit; pyrender culls back faces, 24-bit depth):")
        for name in names:
            scene = bs.ALL_SCENES[name]()
            intr = bs.intrinsics(*bs.RESOLUTIONS[CHECK_RESOLUTION])
            ref = _raycast(scene, bs.orbit_poses(scene, frames)[0], intr)
            ours = ask("ours", "frame", name, CHECK_RESOLUTION, frames)
            theirs = ask("pyrender", "frame", name, CHECK_RESOLUTION, frames)
            print(f"{name:<20} ours     {_compare(*ours, *ref)}")
            print(f"{'':<20} pyrender {_compare(*theirs, *ref)}", flush=True)

    print("\nend to end with HDF5 at 640x480 (depth + normals + instance + class maps; writer created, every "
          "keypoint written while the next renders, file finalized - all timed) vs the raw label pass; target >= 0.8")
    for name in names:
        for compression in compressions:
            raw, full, size = [], [], 0.0
            for r in range(rounds):
                for kind in (("raw", "hdf5") if r % 2 == 0 else ("hdf5", "raw")):
                    if kind == "raw":
                        raw.append(ask("ours", "raw", name, "640x480", frames))
                    else:
                        value, size = ask("ours", "hdf5", name, "640x480", frames, compression)
                        full.append(value)
            a, b = statistics.median(raw), statistics.median(full)
            print(f"{name:<20} {compression:<9} raw {a:6.1f} fps  with HDF5 {b:6.1f} fps  ratio {b / a:.2f} "
                  f"{'ok ' if b / a >= 0.8 else 'LOW'}  ({size / 1e6:.2f} MB per keypoint)", flush=True)

    print(f"\nload average at the end: {os.getloadavg()[0]:.1f}")
    for conn, process in workers.values():
        conn.send(None)
        process.join(timeout=10)


if __name__ == "__main__":
    main()
