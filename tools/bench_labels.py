"""Label throughput: hybridgen's raster pass vs pyrender, and end-to-end with HDF5 writing.

Run: .venv/bin/python tools/bench_labels.py [--frames 12] [--quick]

Each engine lives in its own process (two OpenGL contexts in one process would fight over which is
current); the parent alternates them scene by scene, round by round, so machine noise hits both alike.
Frames/s are medians over rounds; readback and turning the raw buffers into arrays are included:
hybridgen: depth + normals + instance ids (+ class map); pyrender: depth + segmentation (one SEG pass).
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _ours_worker(conn) -> None:  # type: ignore[no-untyped-def]
    import bench_scenes as bs
    import hybridgen as hg
    from hybridgen.render.keypoint_loop import run_keypoints
    from hybridgen.render.render_labels import LabelProducer

    cache: dict = {}
    while True:
        message = conn.recv()
        if message is None:
            return
        kind, scene_name, resolution, frames, *options = message
        key = (scene_name, resolution)
        if key not in cache:
            scene = bs.SCENES[scene_name]()
            scene.camera.intrinsics = bs.intrinsics(*bs.RESOLUTIONS[resolution])
            view = hg.RasterView(scene)
            request = hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"])
            cache[key] = (scene, view, request, request.tables(view), bs.orbit_poses(scene, frames))
            view.render_raw(cache[key][4][0])  # warm-up
        scene, view, request, tables, poses = cache[key]
        if kind == "raw":  # the real label path (two-deep pipeline), values handed to no writer
            for pose in poses:
                scene.camera.add_keypoint(pose)
            producer = LabelProducer(scene, request, view=view)
            start = time.perf_counter()
            run_keypoints(scene, [], [producer])
            conn.send(len(poses) / (time.perf_counter() - start))
            scene.camera.keypoints.clear()
        elif kind == "hdf5":
            for pose in poses:
                scene.camera.add_keypoint(pose)
            with tempfile.TemporaryDirectory() as tmp:
                writer = hg.Hdf5SingleFileWriter(Path(tmp) / "data.hdf5", compression=options[0])
                start = time.perf_counter()
                hg.render_labels(scene, [writer], request, view=view)
                writer.finalize({"object_states": [o.state() for o in scene.objects]})
                elapsed = time.perf_counter() - start
            scene.camera.keypoints.clear()
            conn.send(len(poses) / elapsed)


def _pyrender_worker(conn) -> None:  # type: ignore[no-untyped-def]
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    import numpy as np

    if not hasattr(np, "infty"):
        np.infty = np.inf  # pyrender 0.1.45 still uses the alias removed in NumPy 2
    import pyrender
    import trimesh

    import bench_scenes as bs

    cache: dict = {}
    while True:
        message = conn.recv()
        if message is None:
            return
        _, scene_name, resolution, frames = message
        key = (scene_name, resolution)
        if key not in cache:
            ours = bs.SCENES[scene_name]()
            width, height = bs.RESOLUTIONS[resolution]
            intr = bs.intrinsics(width, height)
            scene = pyrender.Scene()
            seg = {}
            for obj in ours.objects:
                mesh = trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False)
                node = scene.add(pyrender.Mesh.from_trimesh(mesh, smooth=False))
                seg[node] = [obj.instance_id % 256, obj.instance_id // 256, 0]
            K = intr.K
            camera = pyrender.IntrinsicsCamera(K[0, 0], K[1, 1], K[0, 2] + 0.5, K[1, 2] + 0.5,
                                               znear=intr.clip_start, zfar=intr.clip_end)
            camera_node = scene.add(camera)
            renderer = pyrender.OffscreenRenderer(width, height)
            poses = [p @ np.diag([1.0, -1.0, -1.0, 1.0]) for p in bs.orbit_poses(ours, frames)]  # OpenGL axes
            cache[key] = (scene, camera_node, renderer, seg, poses)
            scene.set_pose(camera_node, poses[0])
            renderer.render(scene, flags=pyrender.RenderFlags.SEG, seg_node_map=seg)  # warm-up
        scene, camera_node, renderer, seg, poses = cache[key]
        start = time.perf_counter()
        for pose in poses:
            scene.set_pose(camera_node, pose)
            color, depth = renderer.render(scene, flags=pyrender.RenderFlags.SEG, seg_node_map=seg)
            ids = color[..., 0].astype(np.int32) + 256 * color[..., 1].astype(np.int32)  # noqa: F841
        conn.send(len(poses) / (time.perf_counter() - start))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=12, help="keypoints per round")
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds per scene and engine")
    parser.add_argument("--quick", action="store_true", help="640x480 only, fewer frames")
    parser.add_argument("--compression", nargs="+", default=["gzip", "lzf", "none"],
                        help="HDF5 compressions to time end to end")
    parser.add_argument("--skip-pyrender", action="store_true", help="only the HDF5 end-to-end part")
    args = parser.parse_args()
    resolutions = ["640x480"] if args.quick else ["640x480", "1280x720"]
    frames = 4 if args.quick else args.frames
    spawn = mp.get_context("spawn")
    workers = {}
    for name, target in (("ours", _ours_worker), ("pyrender", _pyrender_worker)):
        parent, child = spawn.Pipe()
        process = spawn.Process(target=target, args=(child,), daemon=True)
        process.start()
        workers[name] = (parent, process)

    def ask(name: str, message: tuple) -> float:
        conn, _ = workers[name]
        conn.send(message)
        return float(conn.recv())

    import bench_scenes as bs

    print(f"{'scene':<18} {'resolution':<10} {'triangles':>10} {'ours fps':>9} {'pyrender fps':>13} {'ratio':>6}")
    rows = []
    for scene_name in [] if args.skip_pyrender else bs.SCENES:
        triangles = bs.SCENES[scene_name]().triangle_count
        for resolution in resolutions:
            ours, theirs = [], []
            for _ in range(args.rounds):
                ours.append(ask("ours", ("raw", scene_name, resolution, frames)))
                theirs.append(ask("pyrender", ("raw", scene_name, resolution, frames)))
            a, b = statistics.median(ours), statistics.median(theirs)
            rows.append((scene_name, resolution, a, b))
            print(f"{scene_name:<18} {resolution:<10} {triangles:>10,} {a:>9.1f} {b:>13.1f} {a / b:>6.2f}", flush=True)
    print("\nend to end with HDF5 (depth + normals + instance + class maps, written while the next keypoint renders):")
    for scene_name in bs.SCENES:
        for compression in args.compression:
            raw, full = [], []
            for _ in range(args.rounds):
                raw.append(ask("ours", ("raw", scene_name, "640x480", frames)))
                full.append(ask("ours", ("hdf5", scene_name, "640x480", frames, compression)))
            a, b = statistics.median(raw), statistics.median(full)
            print(f"{scene_name:<18} 640x480 {compression:<5} raw {a:6.1f} fps  with HDF5 {b:6.1f} fps  "
                  f"ratio {b / a:.2f}", flush=True)
    for conn, process in workers.values():
        conn.send(None)
        process.join(timeout=10)


if __name__ == "__main__":
    main()
