"""Label throughput: hybridgen's raster pass vs pyrender, and end to end with HDF5 writing.

Over 300 lines: the two engines' worker processes and the four tables they answer (whole processes, raw vs end to
end, raster vs pyrender, agreement) are one benchmark; its helpers live in label_*.py, stored_forms.py, harness.py.

Run: .venv/bin/python tools/bench_labels.py [--frames 8] [--rounds 5] [--quick] [--breakdown]
     .venv/bin/python tools/bench_labels.py --e2e-only [--e2e-keypoints 120] [--baseline OTHER_CHECKOUT]
Needs the ``bench`` extras (pyrender, pybullet for the real meshes, embreex for ``--check``).

Each engine lives in its own process (two OpenGL contexts in one process would fight over which is
current); the parent alternates them round by round (and which goes first), so machine noise hits both alike.
A round renders ``--frames`` orbit poses after an untimed warm-up; frames/s are medians over rounds.
Readback and turning the raw buffers into arrays are included on both sides:
  hybridgen: the real label path (two-deep submit/collect pipeline) making depth + normals + instance ids
             + class ids (+ the per-keypoint instance records) in the form the default HDF5 file stores them
             (packed targets, render/raster/label_targets.py), handed to a sink that discards them ("raw");
  pyrender:  one ``render(flags=SEG)`` per keypoint (colour-coded instance ids + depth), ids decoded.
``--check`` compares both engines' depth and ids at one pose with an Embree ray cast through pixel centres.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from harness import Table, alternating, load_average, paired_ratio, run_process

TOOLS = Path(__file__).resolve().parent
PYRENDER = [sys.executable, str(TOOLS / "pyrender_reference.py")]
"""The competitor's whole process (tools/pyrender_reference.py), followed by its spec."""

CHECK_RESOLUTION = "640x480"
E2E_KEYPOINTS = 16


def _ours_worker(conn: Any, checkout: str | None = None) -> None:
    if checkout is not None:  # --baseline: that checkout's hybridgen (this one's label_scenes)
        sys.path.insert(0, checkout)
    import label_scenes as bs  # imports hybridgen: only now, after the checkout went first on sys.path
    import numpy as np
    from stored_forms import default_file_encodings

    import hybridgen as hg
    from hybridgen.render.keypoint_loop import run_keypoints
    from hybridgen.render.raster.raster_passes import depth as depth_pass
    from hybridgen.render.raster.label_producer import LabelProducer

    request = hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"])
    views: dict[str, tuple[Any, Any]] = {}

    class StoredFormSink:
        """Discards every value, but takes the passes in the form the default HDF5 file stores them (asked of
        a real writer, once per scene and size): the raw pass then makes what the end-to-end run makes."""

        tags: dict[str, str] = {}

        def begin(self, n: int, layouts: list[Any], records: dict[str, Any], attributes: dict[str, Any]) -> None:
            key = tuple((layout.key, layout.shape, layout.value_range) for layout in layouts)
            if key not in probed:
                probed[key] = default_file_encodings(n, layouts, records, attributes)
            self.tags = probed[key]

        def accepted_encodings(self) -> dict[str, str]:
            return self.tags

        def write(self, index: int, values: dict[str, Any]) -> None:
            pass

        def end(self) -> None:
            pass

    probed: dict[Any, dict[str, str]] = {}
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
            label_pass(scene, view, poses[name, frames][:2], [StoredFormSink()])
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
            conn.send(len(keypoints) / label_pass(scene, view, keypoints, [StoredFormSink()]))
        elif kind == "hdf5":  # writer built, every keypoint written, file finalized: all timed
            compression = options[0]
            if compression == "blosc2-all":  # a variant measured: Blosc2 LZ4 for the normal codes too
                import hybridgen.io.hdf5_single as hs
                compression, chunks = "blosc2", hs.blosc2_chunks
                hs.blosc2_chunks = lambda stored, level, chunks=chunks: chunks(stored, level) or (
                    hs.Blosc2Chunks("lz4", level, "none", stored.dtype.itemsize) if stored.dtype.itemsize > 1 else None)
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "data.hdf5"
                start = time.perf_counter()
                writer = (hg.Hdf5SingleFileWriter(path) if compression == "default" else
                          hg.Hdf5SingleFileWriter(path, compression=compression))
                label_pass(scene, view, keypoints, [writer])
                writer.finalize({"object_states": [o.state() for o in scene.objects]})
                elapsed = time.perf_counter() - start
                conn.send((len(keypoints) / elapsed, path.stat().st_size / len(keypoints)))
            if options[0] == "blosc2-all":
                hs.blosc2_chunks = chunks
        elif kind == "frame":
            raw = view.render_raw(keypoints[0])
            conn.send((depth_pass(raw), raw.instance.astype(np.int32)))
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
    import label_scenes as bs
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

# ---------------------------------------------------------------- whole processes
def check_output(path: Path, spec: Path) -> None:
    """Stop if the run did not see what pyrender sees (a pose convention gone wrong renders empty images
    very fast): the hit fraction of keypoint 0 must match a pyrender render's within 2 %."""
    import json

    import h5py
    import numpy as np

    with h5py.File(path, "r") as h5:
        ours = float(np.mean(np.isfinite(h5["depth"][0])))
    done = subprocess.run([*PYRENDER, str(spec), "--hit-fraction"], capture_output=True, text=True, check=True)
    theirs = float(done.stdout.split()[-1])
    if abs(ours - theirs) > 0.02:
        raise SystemExit(f"hybridgen sees {ours:.1%} of the pixels hit, pyrender {theirs:.1%}: poses differ "
                         f"({json.loads(spec.read_text())['meshes'][0]['path']})")


def whole_process_table(names: list[str], resolutions: list[str], count: int, rounds: int,
                        ask: Any, cache_dir: Path, render_threads: int = 1,
                        e2e_keypoints: int = E2E_KEYPOINTS) -> None:
    """The issue's table: whole ``hybridgen run`` vs the pyrender script, alternating, plus raw / in-process
    end-to-end label fps (alternating, ``e2e_keypoints`` keypoints, medians of ``rounds``) and their ratio, bytes
    per keypoint and time to first keypoint (1-keypoint runs)."""
    from label_configs import write_configs

    hybridgen = [sys.executable, "-m", "hybridgen"]  # the package on sys.path (PYTHONPATH: another checkout)
    env = dict(os.environ, HYBRIDGEN_CACHE_DIR=str(cache_dir))

    def run_timed(command: list[str], environment: dict[str, str], cpu: list[float] | None = None) -> float:
        """Wall seconds of one whole process; appends its CPU seconds (llvmpipe's threads too) to ``cpu``."""
        finished = run_process(command, environment)
        if cpu is not None:
            cpu.append(finished.cpu)
        return finished.wall

    print(f"\nwhole processes, {count} keypoints, {rounds} alternating rounds, medians; 1st kp = a whole run of one "
          "keypoint (cold cache: once, with an empty mesh cache); hybridgen run = labels-only "
          "config (depth + normals + class + instance, default writer); pyrender = script loading the same files, "
          "rendering depth + seg of the same poses, writing nothing; ratio = pyrender's wall time / ours, cpu ratio = "
          "the same for CPU seconds of the whole processes (user + system, every thread); raw fps = the label pass "
          "in process making the stored forms, handed to no writer; e2e fps = the same with the default HDF5 writer "
          "(gzip; created, written, finalized); e2e/raw = their ratio (goal >= 0.9); mesh cache in "
          f"{cache_dir} (warmed by an untimed run)")
    table = Table([("scene", "<20"), ("resolution", "<10"), ("raw fps", ">8.1f"), ("e2e fps", ">8.1f"),
                   ("e2e/raw", ">7.2f"), ("run fps", ">8.1f"), ("pyrender", ">9.1f"), ("ratio", ">6.2f"),
                   ("cpu ratio", ">9.2f"), ("MB/kp", ">6.2f"), ("1st kp run s", ">12.2f"), ("cold cache s", ">12.2f"),
                   ("1st kp pyr s", ">12.2f")])
    table.header()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name in names:
            for resolution in resolutions:
                config, spec = write_configs(name, resolution, count, work / "configs")
                config1, spec1 = write_configs(name, resolution, 1, work / "configs")
                threaded = write_configs(name, resolution, count, work / "configs", render_threads)[0]
                out = work / "out"
                ours_cmd = [*hybridgen, "run", "--quiet", str(config), str(out)]
                theirs_cmd = [*PYRENDER, str(spec)]
                shutil.rmtree(work / "warm", ignore_errors=True)  # an existing output would be resumed
                cold_env = dict(env, HYBRIDGEN_CACHE_DIR=str(work / f"cold_cache_{len(list(work.iterdir()))}"))
                cold = run_timed([*hybridgen, "run", "--quiet", str(config1), str(work / "warm")], cold_env)
                shutil.rmtree(work / "warm", ignore_errors=True)
                run_timed([*hybridgen, "run", "--quiet", str(config1), str(work / "warm")], env)  # warms caches
                times: dict[str, list[float]] = {"ours": [], "theirs": [], "ours1": [], "theirs1": [], "threads": []}
                cpu: dict[str, list[float]] = {"ours": [], "theirs": [], "threads": []}
                size = 0
                engines = ("threads", "ours", "theirs") if render_threads > 1 else ("ours", "theirs")
                for r in range(rounds):  # threads: the same config on render_threads raster threads, same rounds
                    for engine in alternating(engines, r):
                        if engine == "threads":
                            shutil.rmtree(out, ignore_errors=True)
                            times["threads"].append(run_timed([*hybridgen, "run", "--quiet", str(threaded), str(out)],
                                                              env, cpu["threads"]))
                            check_output(out / "data.hdf5", spec)
                        elif engine == "ours":
                            shutil.rmtree(out, ignore_errors=True)
                            times["ours"].append(run_timed(ours_cmd, env, cpu["ours"]))
                            size = sum(f.stat().st_size for f in out.rglob("*.hdf5"))
                            check_output(out / "data.hdf5", spec)
                            shutil.rmtree(work / "one", ignore_errors=True)
                            times["ours1"].append(run_timed([*hybridgen, "run", "--quiet", str(config1),
                                                             str(work / "one")], env))
                        else:
                            times["theirs"].append(run_timed(theirs_cmd, env, cpu["theirs"]))
                            times["theirs1"].append(run_timed([*PYRENDER, str(spec1)], env))
                med = {k: statistics.median(v) for k, v in times.items()}
                raws, e2es = [], []
                for r in range(rounds):
                    for kind in alternating(("raw", "hdf5"), r):
                        if kind == "raw":
                            raws.append(ask("ours", "raw", name, resolution, e2e_keypoints))
                        else:
                            e2es.append(ask("ours", "hdf5", name, resolution, e2e_keypoints, "default")[0])
                raw, e2e = statistics.median(raws), statistics.median(e2es)
                table.row(name, resolution, raw, e2e, e2e / raw, count / med["ours"], count / med["theirs"],
                          med["theirs"] / med["ours"],
                          statistics.median(cpu["theirs"]) / statistics.median(cpu["ours"]),
                          size / count / 1e6, med["ours1"], cold, med["theirs1"])
                if render_threads > 1:
                    print(f"{'':<20} {'':<10} render_threads {render_threads}: run fps {count / med['threads']:.1f}, "
                          f"ratio {med['theirs'] / med['threads']:.2f}, cpu ratio "
                          f"{statistics.median(cpu['theirs']) / statistics.median(cpu['threads']):.2f}", flush=True)


def e2e_table(names: list[str], resolutions: list[str], count: int, rounds: int, ask: Any,
              checkouts: list[str], compressions: list[str]) -> None:
    """Raw vs end-to-end label fps in process (the e2e/raw goal) per scene and resolution: medians of ``rounds``
    rounds; in each round every checkout's raw pass and writer run per compression ("default": the writer's
    default), in an order that alternates."""
    print(f"\nin process, {count} keypoints per measurement, {rounds} alternating rounds, medians; raw = the label "
          "pass making the stored forms, no writer; e2e = the same with the default HDF5 writer (created, every "
          "keypoint written, finalized); ratio = median over rounds of e2e / raw of the same round; load average "
          f"{load_average():.1f} at the start")
    table = Table([("scene", "<20"), ("resolution", "<10"), ("checkout", "<9"), ("writer", "<13"),
                   ("raw fps", ">8.1f"), ("e2e fps", ">8.1f"), ("e2e/raw", ">7.2f"), ("MB/kp", ">6.2f")])
    table.header()
    for name in names:
        for resolution in resolutions:
            fps: dict[tuple[str, str], list[float]] = {}
            size: dict[tuple[str, str], float] = {}
            for r in range(rounds):
                runs = [(checkout, kind) for checkout in checkouts for kind in ("raw", *compressions)]
                for checkout, kind in alternating(runs, r):
                    if kind == "raw":
                        fps.setdefault((checkout, kind), []).append(ask(checkout, "raw", name, resolution, count))
                    else:
                        value, size[checkout, kind] = ask(checkout, "hdf5", name, resolution, count, kind)
                        fps.setdefault((checkout, kind), []).append(value)
            for checkout in checkouts:
                raw = fps[checkout, "raw"]
                for compression in compressions:
                    e2e = fps[checkout, compression]
                    table.row(name, resolution, "this" if checkout == "ours" else checkout, compression,
                              statistics.median(raw), statistics.median(e2e), paired_ratio(e2e, raw),
                              size[checkout, compression] / 1e6)
    print(f"load average at the end: {load_average():.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=8, help="orbit poses (keypoints) per round")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds per scene, resolution and engine")
    parser.add_argument("--quick", action="store_true", help="smoke check: 640x480 only, 4 frames, 2 rounds, gzip")
    parser.add_argument("--scenes", nargs="+", help="scene names (default: the three standard ones); "
                        "'1.3M icosphere' is an extra")
    parser.add_argument("--compression", nargs="+", choices=["gzip", "lzf", "none"],
                        help="HDF5 compressions to time end to end with --inner (default: all; --quick: gzip)")
    parser.add_argument("--check", action=argparse.BooleanOptionalAction, default=None,
                        help="depth/id agreement of both engines with a ray cast (default: on unless --quick)")
    parser.add_argument("--breakdown", action="store_true", help="also time our stages serially per keypoint")
    parser.add_argument("--skip-pyrender", action="store_true", help="only the HDF5 end-to-end part")
    parser.add_argument("--keypoints", type=int, default=120, help="keypoints of the whole-process runs")
    parser.add_argument("--render-threads", type=int, default=1, help="also time the whole-process runs with "
                        "this many raster threads (SegMapRenderer render_threads), in the same rounds")
    parser.add_argument("--whole-rounds", type=int, default=3, help="alternating rounds of the whole-process runs")
    parser.add_argument("--inner", action="store_true", help="also the in-process sections: raster pass vs "
                        "pyrender, --breakdown, --check, end to end per compression")
    parser.add_argument("--e2e-only", action="store_true", help="only raw vs end to end in process (the e2e/raw "
                        "goal), --rounds alternating rounds per scene and resolution")
    parser.add_argument("--e2e-keypoints", type=int, default=E2E_KEYPOINTS, help="keypoints of each in-process raw "
                        "and end-to-end measurement (writer created, every keypoint written, file finalized)")
    parser.add_argument("--e2e-compression", nargs="+", default=["default"],
                        choices=["default", "gzip", "blosc2", "blosc2-all", "lzf", "none"],
                        help="with --e2e-only: writer compressions timed in the same rounds (blosc2-all: a variant, "
                        "Blosc2 LZ4 for the normal codes too)")
    parser.add_argument("--baseline", type=Path, help="with --e2e-only: also time another checkout's hybridgen "
                        "(e.g. git archive <commit> | tar -x -C /tmp/base) in the same rounds")
    parser.add_argument("--cache-dir", type=Path, help="HYBRIDGEN_CACHE_DIR of the whole-process runs "
                        "(default: a fresh temporary folder, warmed by an untimed run)")
    args = parser.parse_args()

    import label_scenes as bs

    names = args.scenes or list(bs.SCENES)
    unknown = [n for n in names if n not in bs.ALL_SCENES]
    if unknown:
        parser.error(f"unknown scene(s) {unknown}; known: {list(bs.ALL_SCENES)}")
    resolutions = ["640x480"] if args.quick else list(bs.RESOLUTIONS)
    frames = 4 if args.quick else args.frames
    rounds = 2 if args.quick else args.rounds
    compressions = args.compression or (["gzip"] if args.quick else ["gzip", "lzf", "none"])
    check = (not args.quick) if args.check is None else args.check

    spawn = mp.get_context("spawn")
    workers = {}
    engines: list[tuple[str, Any, tuple[Any, ...]]] = [("ours", _ours_worker, ())]
    if not (args.skip_pyrender or args.e2e_only):
        engines.append(("pyrender", _pyrender_worker, ()))
    if args.baseline is not None:
        if not args.e2e_only:
            parser.error("--baseline needs --e2e-only")
        if not (args.baseline / "hybridgen" / "__init__.py").is_file():
            parser.error(f"--baseline {args.baseline}: no hybridgen package there")
        engines.append(("baseline", _ours_worker, (str(args.baseline.resolve()),)))
    for engine, target, extra in engines:
        parent, child = spawn.Pipe()
        process = spawn.Process(target=target, args=(child, *extra), daemon=True)
        process.start()
        workers[engine] = (parent, process)

    def ask(engine: str, *message: Any) -> Any:
        conn, _ = workers[engine]
        conn.send(message)
        return conn.recv()

    triangles = {name: bs.ALL_SCENES[name]().triangle_count for name in names}
    print(f"{frames} keypoints per round, {rounds} rounds, median frames/s; ours = depth + normals + instance + class; "
          f"{os.cpu_count()} CPUs, load average {load_average():.1f} (other processes skew absolute numbers)")
    if args.e2e_only:
        e2e_table(names, resolutions, args.e2e_keypoints, args.rounds, ask, ["ours", *workers.keys() & {"baseline"}],
                  args.e2e_compression)
        for conn, process in workers.values():
            conn.send(None)
            process.join(timeout=10)
        return
    with tempfile.TemporaryDirectory() as cache:
        whole_process_table(names, resolutions, 20 if args.quick else args.keypoints,
                            2 if args.quick else args.whole_rounds, ask, args.cache_dir or Path(cache),
                            args.render_threads, args.e2e_keypoints)
    if not args.inner:
        for conn, process in workers.values():
            conn.send(None)
            process.join(timeout=10)
        return
    if not args.skip_pyrender:
        print()
        table = Table([("scene", "<20"), ("resolution", "<10"), ("triangles", ">10,"), ("ours fps", ">9.1f"),
                       ("pyrender fps", ">13.1f"), ("ours/pyrender", ">14.2f")])
        table.header()
        for name in names:
            for resolution in resolutions:
                fps: dict[str, list[float]] = {"ours": [], "pyrender": []}
                for r in range(rounds):
                    for engine in alternating(("ours", "pyrender"), r):
                        fps[engine].append(ask(engine, "raw", name, resolution, frames))
                a, b = statistics.median(fps["ours"]), statistics.median(fps["pyrender"])
                table.row(name, resolution, triangles[name], a, b, a / b)

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
                for kind in alternating(("raw", "hdf5"), r):
                    if kind == "raw":
                        raw.append(ask("ours", "raw", name, "640x480", frames))
                    else:
                        value, size = ask("ours", "hdf5", name, "640x480", frames, compression)
                        full.append(value)
            a, b = statistics.median(raw), statistics.median(full)
            print(f"{name:<20} {compression:<9} raw {a:6.1f} fps  with HDF5 {b:6.1f} fps  ratio {b / a:.2f} "
                  f"{'ok ' if b / a >= 0.8 else 'LOW'}  ({size / 1e6:.2f} MB per keypoint)", flush=True)

    print(f"\nload average at the end: {load_average():.1f}")
    for conn, process in workers.values():
        conn.send(None)
        process.join(timeout=10)


if __name__ == "__main__":
    main()
