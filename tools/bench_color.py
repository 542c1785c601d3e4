"""Color rendering: hybridgen vs a bare Mitsuba script on the same scene, and vs Blender Cycles (one run).

Over 300 lines: the bare script, the interleaving sink and the report of one run that times all three engines
keypoint by keypoint; Cycles lives in cycles_export.py / cycles_worker.py, timing and tables in harness.py.

Run: .venv/bin/python tools/bench_color.py [--res 640x480] [--spp 64] [--bounces 6] [--no-cycles] [--quick]
     .venv/bin/python tools/bench_color.py --quality [--res 320x240] [--reference-spp 4096] [--scenes a,b]
         (defaults vs Cycles at BlenderProc's defaults, the issue's settings: runs tools/bench_color_quality.py
         with the other options)

Scene: a closed 6 x 6 x 3 m room (floor, four walls, emissive ceiling), 20 primitives and a 100,000-triangle
torus knot; 8 camera poses inside the room (everything seeded).

(a) hybridgen's own API, ``render_color(scene, [sink], PathTraceSettings(...), seed=...)``, renders the 8
    keypoints into a MemorySink. The sink's ``write`` (called once per keypoint, right after hybridgen made
    it) times hybridgen's keypoint and runs the competitors, so the engines alternate keypoint by keypoint
    (ABBA: keypoint 2k runs hybridgen first, 2k+1 the competitors first) and share the machine's noise.
    The bare Mitsuba script loads the same scene dictionary once and renders each pose by updating a plain
    ``perspective`` sensor through ``mi.traverse`` - the cheapest way Mitsuba can re-render a pose.
    Reported: setup (scene load), the first keypoint (kernel compilation; a fresh Dr.Jit kernel cache is
    used unless --warm-cache), the steady state, the overhead over all keypoints, Dr.Jit kernels launched /
    compiled per keypoint (kernel history), RSS per keypoint, CPU use per keypoint (2.0 = both cores; less
    means another process took CPU), and a 1-spp run with a profile of hybridgen's fixed per-keypoint cost.
(b) Blender Cycles on the CPU (``bpy`` from PyPI in its own ``.venv-bpy``, created on first use; skipped
    with --no-cycles or if that fails): same meshes and normals, resolution, spp, bounces (Cycles
    max_bounces b == Mitsuba max_depth b + 2), Russian-roulette start, one-pixel box filter, 2 threads,
    persistent data, with and without its light tree. It runs in a worker process that renders one
    keypoint per request, interleaved with (a).
"""
from __future__ import annotations

import argparse
import cProfile
import io
import math
import os
import pstats
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from cycles_export import export_for_cycles
from cycles_worker import CyclesWorker, ensure_bpy_venv
from harness import Stopwatch, Table, accumulating, alternating, load_average, paired_ratio, rss_mib

REPO = Path(__file__).resolve().parents[1]
VARIANT = "llvm_ad_rgb"  # hybridgen's automatic choice on a machine without CUDA (checked at run time)


# --------------------------------------------------------------------------------------------- scene
def torus_knot(p: int = 2, q: int = 3, segments: int = 1000, sides: int = 50, size: float = 0.5,
               tube: float = 0.07) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A (p, q) torus knot tube: vertices, faces (2 x segments x sides triangles) and analytic normals."""
    t = np.linspace(0, 2 * np.pi, segments, endpoint=False)

    def curve(t: np.ndarray) -> np.ndarray:
        r = 2 + np.cos(q * t)
        return np.stack([r * np.cos(p * t), r * np.sin(p * t), -np.sin(q * t)], axis=1) * size / 3

    centre = curve(t)
    tangent = curve(t + 1e-4) - curve(t - 1e-4)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    normal = centre - np.sum(centre * tangent, axis=1, keepdims=True) * tangent  # away from the knot's axis
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    binormal = np.cross(tangent, normal)
    s = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    ring = np.cos(s)[None, :, None] * normal[:, None] + np.sin(s)[None, :, None] * binormal[:, None]
    vertices = (centre[:, None] + tube * ring).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    a, b = i * sides + j, ((i + 1) % segments) * sides + j
    c, d = ((i + 1) % segments) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
    # Wound so that the geometric normals point outwards, as the vertex normals do.
    faces = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return vertices, faces, ring.reshape(-1, 3)


def bench_scene(width: int, height: int, keypoints: int = 8, seed: int = 7) -> Any:
    """The room, 20 primitives on the floor, the 100k-triangle knot and ``keypoints`` poses looking at it."""
    import hybridgen as hg

    rng = np.random.default_rng(seed)
    scene = hg.Scene()
    walls = (("floor", [0, 0, 0], [0, 0, 0], (0.55, 0.5, 0.45)),
             ("north", [0, 3, 1.5], [math.pi / 2, 0, 0], (0.7, 0.7, 0.65)),
             ("south", [0, -3, 1.5], [-math.pi / 2, 0, 0], (0.7, 0.7, 0.65)),
             ("east", [3, 0, 1.5], [0, -math.pi / 2, 0], (0.6, 0.65, 0.7)),
             ("west", [-3, 0, 1.5], [0, math.pi / 2, 0], (0.7, 0.6, 0.6)))
    for name, location, rotation, color in walls:
        wall = hg.make_primitive("plane", 6.0, name=name, category_id=1, color=color,
                                 local2world=hg.object_pose(location, rotation))
        wall.material.specular = 0.0  # diffuse
        scene.add(wall)
    ceiling = hg.make_primitive("plane", 6.0, name="ceiling", category_id=2,
                                local2world=hg.object_pose([0, 0, 3], [math.pi, 0, 0]))
    ceiling.material.specular = 0.0
    ceiling.material.emission, ceiling.material.emission_strength = (1.0, 0.95, 0.9), 1.0
    scene.add(ceiling)
    shapes = ["sphere", "cube", "cylinder", "cone", "torus"]
    placed = 0
    while placed < 20:
        xy = rng.uniform(-2.5, 2.5, 2)
        if np.linalg.norm(xy) < 0.9:  # keep the knot's spot free
            continue
        size = float(rng.uniform(0.3, 0.55))
        obj = hg.make_primitive(shapes[placed % 5], size, name=f"o{placed}", category_id=3,
                                color=tuple(rng.uniform(0.1, 0.9, 3)),
                                local2world=hg.object_pose([*xy, size / 2], [0, 0, rng.uniform(0, 2 * math.pi)]))
        if placed % 2:
            obj.material.specular = 0.0  # diffuse
        else:
            obj.material.specular, obj.material.roughness = 0.5, float(rng.uniform(0.2, 0.6))
            obj.material.metallic = 1.0 if placed % 4 == 0 else 0.0
        scene.add(obj)
        placed += 1
    vertices, faces, normals = torus_knot()
    knot = hg.MeshObject("knot", vertices, faces, vertex_normals=normals, category_id=4,
                         local2world=hg.object_pose([0, 0, 0.9], [0.3, 0.2, 0]))
    knot.material.base_color, knot.material.roughness = (0.8, 0.35, 0.1, 1.0), 0.3
    scene.add(knot)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(math.radians(70), width, height, clip_start=0.05,
                                                     clip_end=100.0)
    for i in range(keypoints):
        angle = 2 * math.pi * i / keypoints + rng.uniform(-0.2, 0.2)
        distance, height_m = rng.uniform(1.8, 2.6), rng.uniform(1.0, 2.0)
        target = [*rng.uniform(-0.2, 0.2, 2), 0.8]
        scene.camera.add_keypoint(hg.look_at([distance * math.cos(angle), distance * math.sin(angle), height_m],
                                             target))
    return scene


# ----------------------------------------------------------------------------------------- measuring
class Kernels:
    """Dr.Jit's kernel history between two calls of :meth:`take`: launches, compilations, seconds."""

    @staticmethod
    def take() -> dict[str, float]:
        import drjit as dr

        launched = compiled = 0
        compile_s = execute_s = 0.0
        for kernel in dr.kernel_history():
            execute_s += kernel.get("execution_time", 0.0) / 1000
            if kernel["type"] != dr.KernelType.JIT:
                continue
            launched += 1
            if not kernel.get("cache_hit"):  # compiled now, or (cache_disk) loaded from the disk cache
                compiled += 1
                compile_s += (kernel.get("codegen_time", 0.0) + kernel.get("backend_time", 0.0)) / 1000
        return {"launched": launched, "compiled": compiled, "compile_s": compile_s, "execute_s": execute_s}


def srgb8(linear: np.ndarray) -> np.ndarray:
    from hybridgen.render.tonemap import to_srgb8

    return to_srgb8(linear)


def blurred_difference(a: np.ndarray, b: np.ndarray, block: int = 8) -> float:
    """Mean absolute difference (0..255) of two sRGB8 images averaged over block x block tiles (the
    engines' noise differs sample by sample; this compares the pictures)."""
    h, w = (a.shape[0] // block) * block, (a.shape[1] // block) * block

    def tiles(x: np.ndarray) -> np.ndarray:
        return x[:h, :w].astype(np.float64).reshape(h // block, block, w // block, block, -1).mean(axis=(1, 3))

    return float(np.abs(tiles(a) - tiles(b)).mean())


# ------------------------------------------------------------------------------------- bare Mitsuba
class BareMitsuba:
    """The bare script: one ``mi.load_dict``, a plain ``perspective`` sensor moved through ``mi.traverse``.

    The dictionary's geometry, materials and emitters come from ``hybridgen.render.pathtrace.mitsuba_scene.scene_dict``
    (so both engines trace exactly the same meshes, BSDFs and emitters - a hand-written copy could differ
    in a detail and measure something else); the integrator is ``PathTraceSettings.integrator()`` (path,
    max_depth = bounces + 2, same rr_depth); sensor, film (one-pixel box filter, RGB) and sampler
    (independent, same spp and seed) are written here with Mitsuba's own plugins.
    """

    def __init__(self, scene: Any, settings: Any) -> None:
        import mitsuba as mi

        from hybridgen.render.pathtrace.mitsuba_scene import scene_dict

        intr = scene.camera.intrinsics
        self.spp = settings.samples
        watch = Stopwatch()
        description = scene_dict(scene)
        self.dict_s = watch.read()[0]
        description["integrator"] = settings.integrator()
        description["sensor"] = {
            "type": "perspective", "fov_axis": "x", "fov": math.degrees(2 * math.atan(intr.width / (2 * intr.K[0, 0]))),
            "principal_point_offset_x": -(intr.K[0, 2] - (intr.width - 1) / 2) / intr.width,
            "principal_point_offset_y": -(intr.K[1, 2] - (intr.height - 1) / 2) / intr.height,
            "near_clip": intr.clip_start, "far_clip": intr.clip_end, "sampler": {"type": "independent"},
            "film": {"type": "hdrfilm", "width": intr.width, "height": intr.height, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}, "sample_border": False}}
        self.scene = mi.load_dict(description)
        self.setup_s = watch.read()[0]
        self.params = mi.traverse(self.scene.sensors()[0])

    def render(self, cam2world: np.ndarray, seed: int) -> np.ndarray:
        import mitsuba as mi

        from hybridgen.render.pathtrace.path_trace import OPENCV_TO_MITSUBA

        self.params["to_world"] = mi.ScalarTransform4f((np.asarray(cam2world) @ OPENCV_TO_MITSUBA).tolist())
        self.params.update()
        return np.array(mi.render(self.scene, spp=self.spp, seed=seed), dtype=np.float32)


# ------------------------------------------------------------------------------------ the interleaving
class TimingSink:
    """A MemorySink that times hybridgen's keypoints and runs the competitors between them.

    hybridgen's keypoint i is the time from the end of the previous ``write`` (or ``begin``) to the start of
    ``write(i)``: that is render_color's whole per-keypoint path (producer, seed, render, sRGB encoding,
    loop). ``competitors(i)`` runs inside ``write`` and is not counted.
    """

    def __init__(self, competitors: Callable[[int], None]) -> None:
        from hybridgen.io.memory_sink import MemorySink

        self.memory = MemorySink()
        self.competitors = competitors
        self.begin_at = 0.0
        self.rows: list[dict[str, Any]] = []
        self._watch = Stopwatch()

    def begin(self, n_keypoints: int, layouts: list, records: dict, attributes: dict) -> None:
        self.begin_at = time.perf_counter()
        self.setup_kernels = Kernels.take()
        self.memory.begin(n_keypoints, layouts, records, attributes)
        self._watch = Stopwatch()

    def write(self, index: int, values: dict[str, Any]) -> None:
        wall, cpu = self._watch.read()
        self.rows.append({"wall": wall, "cpu": cpu, "kernels": Kernels.take(), "rss": rss_mib()})
        self.memory.write(index, values)
        self.competitors(index)
        Kernels.take()  # nothing of the competitors' counts for hybridgen
        self._watch = Stopwatch()

    def end(self) -> None:
        self.memory.end()


def profile_fixed_cost(scene: Any, args: argparse.Namespace, bare_settings: Any) -> None:
    """hybridgen vs the bare script at 1 spp, where the fixed per-keypoint cost is visible, and a cProfile
    of hybridgen's per-keypoint call."""
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings
    from hybridgen.render.render_color import ColorProducer, keypoint_seed

    settings = PathTraceSettings(samples=1, max_bounces=args.bounces)
    producer = ColorProducer(scene, settings, seed=args.seed, variant=VARIANT)
    bare = BareMitsuba(scene, settings)
    poses = scene.camera.keypoints
    for i in range(2):  # compile the 1-spp kernels of both
        producer.produce(i, poses[i])
        bare.render(poses[i], keypoint_seed(args.seed, i))
    ours, theirs, ours_exec, theirs_exec = [], [], [], []
    Kernels.take()
    for rep in range(3):
        for i, pose in enumerate(poses):
            for who in alternating((0, 1), rep + i):
                watch = Stopwatch()
                if who == 0:
                    producer.produce(i, pose)
                    ours.append(watch.read()[0])
                    ours_exec.append(Kernels.take()["execute_s"])
                else:
                    bare.render(pose, keypoint_seed(args.seed, i))
                    theirs.append(watch.read()[0])
                    theirs_exec.append(Kernels.take()["execute_s"])
    m_ours, m_bare = statistics.median(ours), statistics.median(theirs)
    print(f"\nfixed per-keypoint cost (1 spp, {len(ours)} keypoints each, medians): hybridgen {m_ours * 1e3:.1f} ms "
          f"(kernels {statistics.median(ours_exec) * 1e3:.1f} ms), bare {m_bare * 1e3:.1f} ms "
          f"(kernels {statistics.median(theirs_exec) * 1e3:.1f} ms): hybridgen adds {(m_ours - m_bare) * 1e3:+.1f} ms "
          "per keypoint")
    profiler = cProfile.Profile()
    profiler.enable()
    for i, pose in enumerate(poses):
        producer.produce(i, pose)
    profiler.disable()
    text = io.StringIO()
    stats = pstats.Stats(profiler, stream=text).sort_stats("tottime")
    stats.print_stats(8)
    lines = [line for line in text.getvalue().splitlines() if line.strip()]
    start = next(i for i, line in enumerate(lines) if line.lstrip().startswith("ncalls"))
    print(f"cProfile of hybridgen's ColorProducer.produce over {len(poses)} keypoints at 1 spp (top by own time):")
    for line in lines[start:start + 9]:
        print("   " + line.replace(str(REPO) + "/", "").replace(sys.prefix, "<venv>"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="640x480", help="WxH (default 640x480)")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--bounces", type=int, default=6, help="max_bounces, Cycles' meaning (Mitsuba max_depth + 2)")
    parser.add_argument("--keypoints", type=int, default=8)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--quick", action="store_true", help="160x120, 8 spp, no Cycles")
    parser.add_argument("--no-cycles", action="store_true", help="skip Blender Cycles (part b)")
    parser.add_argument("--cycles", action="store_true", help=argparse.SUPPRESS)  # old flag: Cycles is the default
    parser.add_argument("--light-tree", choices=("on", "off", "both"), default="both",
                        help="Cycles' light tree setting(s) to time (default both)")
    parser.add_argument("--bpy-venv", type=Path, default=REPO / ".venv-bpy")
    parser.add_argument("--warm-cache", action="store_true",
                        help="use ~/.drjit's kernel cache (default: a fresh one, so keypoint 1 shows compilation)")
    parser.add_argument("--no-profile", action="store_true", help="skip the 1-spp fixed-cost run and profile")
    parser.add_argument("--quality", action="store_true", help="quality mode: runs tools/bench_color_quality.py "
                        "with the other options (defaults vs Cycles at BlenderProc's defaults; see its --help)")
    if "--quality" in sys.argv[1:]:  # the quality benchmark is its own tool; this flag keeps its old command
        rest = [arg for arg in sys.argv[1:] if arg != "--quality"]
        os.execv(sys.executable, [sys.executable, str(REPO / "tools" / "bench_color_quality.py"), *rest])
    args = parser.parse_args()
    if args.quick:
        args.res, args.spp, args.no_cycles = "160x120", 8, True
    width, height = (int(v) for v in args.res.lower().split("x"))
    tmp = Path(tempfile.mkdtemp(prefix="bench_color_"))
    if not args.warm_cache:  # must be set before Dr.Jit starts (hybridgen's variant probe inherits it)
        os.environ["DRJIT_CACHE_DIR"] = str(tmp / "drjit-cache")

    import drjit as dr
    import mitsuba as mi

    from hybridgen.render.pathtrace import mitsuba_variant, path_trace
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings
    from hybridgen.render.render_color import keypoint_seed, render_color

    load_before = load_average()
    scene = bench_scene(width, height, args.keypoints, seed=7)
    settings = PathTraceSettings(samples=args.spp, max_bounces=args.bounces)
    n = len(scene.camera)
    print(f"scene: room (6 planes) + {len(scene.objects) - 7} primitives + knot ({len(scene.by_name('knot').faces):,} "
          f"triangles): {len(scene.objects)} meshes, {scene.triangle_count:,} triangles; {width}x{height}, {args.spp} spp, "
          f"max_bounces {args.bounces} (Mitsuba max_depth {args.bounces + 2}), {n} keypoints; {os.cpu_count()} cores, "
          f"load average {load_before:.2f} at start")
    print(f"Dr.Jit kernel cache: {'~/.drjit (warm)' if args.warm_cache else 'fresh (cold), ' + os.environ['DRJIT_CACHE_DIR']}")

    # (b) set up first, so that its venv creation and scene sync do not overlap any timing.
    cycles: CyclesWorker | None = None
    tree_modes = {"on": [True], "off": [False], "both": [True, False]}[args.light_tree]
    if not args.no_cycles:
        python = ensure_bpy_venv(args.bpy_venv)
        if python is not None:
            export_for_cycles(scene, tmp / "scene.npz", args.spp, args.bounces, settings.min_bounces)
            try:
                cycles = CyclesWorker(python, tmp / "scene.npz")
                print(f"Cycles: Blender {cycles.hello['blender']} worker ready (scene built in "
                      f"{cycles.hello['setup_s']:.1f} s)")
            except (RuntimeError, ValueError, OSError) as exc:
                print(f"Cycles skipped: {exc}")
                cycles = None
    else:
        print("Cycles: skipped (--no-cycles / --quick)")

    # (a) the bare script's scene first (it pays the cold scene-loading kernels), then render_color.
    mi.set_variant(VARIANT)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    Kernels.take()
    bare = BareMitsuba(scene, settings)
    bare_setup_kernels = Kernels.take()
    bare_rows: dict[int, dict[str, Any]] = {}
    cycles_rows: dict[tuple[int, bool], dict[str, Any]] = {}
    images: dict[str, np.ndarray] = {}

    def run_competitor(i: int) -> None:
        watch = Stopwatch()
        linear = bare.render(scene.camera.keypoints[i], keypoint_seed(args.seed, i))
        wall, cpu = watch.read()
        bare_rows[i] = {"wall": wall, "cpu": cpu, "kernels": Kernels.take(), "rss": rss_mib()}
        if i == 0:
            images["bare"] = srgb8(linear)
        for tree in alternating(tree_modes, i):
            if cycles is not None:
                save = tmp / "cycles0.png" if i == 0 and tree == tree_modes[0] else None
                cycles_rows[(i, tree)] = cycles.render(i, tree, keypoint_seed(args.seed, i), save)

    def competitors(i: int) -> None:  # ABBA: after hybridgen's 2k run 2k and 2k+1, so 2k+1 runs them first
        if i % 2 == 0:
            run_competitor(i)
            if i + 1 < n:
                run_competitor(i + 1)

    # Time the setup parts hybridgen's render_color goes through (wrappers only; nothing else changes).
    setup_parts = {"variant probe": 0.0, "scene_dict": 0.0}

    mitsuba_variant.variant_works = accumulating(setup_parts, "variant probe", mitsuba_variant.variant_works)
    path_trace.scene_dict = accumulating(setup_parts, "scene_dict", path_trace.scene_dict)
    sink = TimingSink(competitors)
    called = time.perf_counter()
    render_color(scene, [sink], settings, seed=args.seed)  # variant: hybridgen's automatic choice
    rss_end = rss_mib()
    variant = sink.memory.attributes.get("mitsuba_variant")
    if cycles is not None:
        cycles.close()
    load_after = load_average()

    # ------------------------------------------------------------------------------------ report (a)
    ours_setup = sink.begin_at - called
    ours = [row["wall"] for row in sink.rows]
    theirs = [bare_rows[i]["wall"] for i in range(n)]
    print(f"\n(a) hybridgen render_color vs bare Mitsuba ({variant}{'' if variant == VARIANT else ' != bare ' + VARIANT})")
    other = ours_setup - sum(setup_parts.values())
    print(f"setup: hybridgen {ours_setup:.2f} s (variant probe in a child process {setup_parts['variant probe']:.2f} s, "
          f"scene_dict {setup_parts['scene_dict']:.2f} s, load_dict + sensor {other:.2f} s; "
          f"{sink.setup_kernels['compiled']} kernels compiled), bare {bare.setup_s:.2f} s (scene_dict "
          f"{bare.dict_s:.2f} s, load_dict {bare.setup_s - bare.dict_s:.2f} s; {bare_setup_kernels['compiled']} "
          "kernels compiled, run first)")
    engine_columns = [("s", ">9.3f"), ("cpu/wall", ">8.2f"), ("kernels (compiled, compile s)", ">29"),
                      ("RSS MiB", ">7.0f")]
    table = Table([("kp", ">3d"), *[(f"hybridgen {t}", f) for t, f in engine_columns],
                   *[(f"bare {t}", f) for t, f in engine_columns], ("ratio", ">6.3f")])
    table.header()
    for i in range(n):
        cells = []
        for row in (sink.rows[i], bare_rows[i]):
            k = row["kernels"]
            kernels = f"{k['launched']:2d} ({k['compiled']}, {k['compile_s']:5.2f})"
            cells += [row["wall"], row["cpu"] / row["wall"], kernels, row["rss"][0]]
        table.row(i, *cells, sink.rows[i]["wall"] / bare_rows[i]["wall"])
    steady_ours, steady_bare = statistics.median(ours[1:]), statistics.median(theirs[1:])
    paired = paired_ratio(ours[1:], theirs[1:])
    exec_ours = statistics.median(row["kernels"]["execute_s"] for row in sink.rows[1:])
    exec_bare = statistics.median(bare_rows[i]["kernels"]["execute_s"] for i in range(1, n))
    overhead = 100 * (sum(ours) / sum(theirs) - 1)
    overhead_setup = 100 * ((ours_setup + sum(ours)) / (bare.setup_s + sum(theirs)) - 1)
    print(f"first keypoint (kernel compilation): hybridgen {ours[0]:.2f} s ({sink.rows[0]['kernels']['compile_s']:.2f} s "
          f"compiling), bare {theirs[0]:.2f} s ({bare_rows[0]['kernels']['compile_s']:.2f} s compiling)")
    print(f"steady keypoints 1..{n - 1} (median): hybridgen {steady_ours:.3f} s, bare re-render {steady_bare:.3f} s; "
          f"ratio {steady_ours / steady_bare:.3f}x (median of paired ratios {paired:.3f}x; target <= 1.1x) "
          f"{'OK' if paired <= 1.1 else 'MISSED'}")
    print(f"  of which Dr.Jit kernels executing: hybridgen {exec_ours:.3f} s, bare {exec_bare:.3f} s; host side "
          f"(tracing, launch, conversion): hybridgen {steady_ours - exec_ours:.3f} s, bare {steady_bare - exec_bare:.3f} s")
    print(f"overhead over all {n} keypoints: hybridgen {sum(ours):.2f} s vs bare {sum(theirs):.2f} s = "
          f"{overhead:+.1f} % (target <= 5 %) {'OK' if overhead <= 5 else 'MISSED'}; with setup "
          f"{ours_setup + sum(ours):.2f} s vs {bare.setup_s + sum(theirs):.2f} s = {overhead_setup:+.1f} %")
    recompiled = sum(row["kernels"]["compiled"] for row in sink.rows[1:])
    growth = sink.rows[-1]["rss"][0] - sink.rows[1]["rss"][0]
    print(f"kernels compiled after the first keypoint: hybridgen {recompiled}, bare "
          f"{sum(bare_rows[i]['kernels']['compiled'] for i in range(1, n))} (0 = no recompilation per pose)")
    print(f"RSS: after keypoint 1 {sink.rows[1]['rss'][0]:.0f} MiB, after keypoint {n - 1} {sink.rows[-1]['rss'][0]:.0f} "
          f"MiB ({growth:+.0f} MiB, of which the MemorySink holds {n * width * height * 3 / 2**20:.1f} MiB of colors), "
          f"after render_color {rss_end[0]:.0f} MiB, peak {rss_end[1]:.0f} MiB")
    ours0 = sink.memory.frames[0]["colors"]
    print(f"same picture check, keypoint 0: mean sRGB hybridgen {ours0.mean():.2f}, bare {images['bare'].mean():.2f}; "
          f"8x8-tile mean abs difference {blurred_difference(ours0, images['bare']):.2f} / 255")

    # ------------------------------------------------------------------------------------ report (b)
    if cycles is not None and cycles_rows:
        print(f"\n(b) Blender Cycles {cycles.hello['blender']} on the CPU ({os.cpu_count()} threads, max_bounces "
              f"{args.bounces}, {args.spp} spp, no adaptive sampling, no denoising, persistent data)")
        table = Table([("kp", ">3d"), ("hybridgen s", ">11.3f"),
                       *[column for t in tree_modes for column in
                         ((f"Cycles light tree {'on' if t else 'off'} s", ">22.3f"), ("cpu/wall", ">8.2f"),
                          ("hybridgen/Cycles", ">16.3f"))]])
        table.header()
        for i in range(n):
            cells = []
            for tree in tree_modes:
                row = cycles_rows[(i, tree)]
                cells += [row["seconds"], row["cpu_s"] / row["seconds"], ours[i] / row["seconds"]]
            table.row(i, ours[i], *cells)
        for tree in tree_modes:
            times = [cycles_rows[(i, tree)]["seconds"] for i in range(n)]
            steady = statistics.median(times[1:])
            per_kp = paired_ratio(ours[1:], times[1:])
            print(f"light tree {'on ' if tree else 'off'}: first {times[0]:.2f} s, steady {steady:.3f} s (median); "
                  f"Mitsuba (hybridgen) / Cycles per keypoint = {per_kp:.2f} (median of keypoints 1..{n - 1}), "
                  f"bare Mitsuba / Cycles = {paired_ratio(theirs[1:], times[1:]):.2f}")
        if cycles.peak_rss_mib:
            print(f"Cycles worker peak RSS {cycles.peak_rss_mib:.0f} MiB")
        if (tmp / "cycles0.png").exists():
            from PIL import Image

            picture = np.asarray(Image.open(tmp / "cycles0.png").convert("RGB"))
            print(f"similar picture check, keypoint 0: mean sRGB Cycles {picture.mean():.2f} vs hybridgen "
                  f"{ours0.mean():.2f}; 8x8-tile mean abs difference {blurred_difference(ours0, picture):.2f} / 255 "
                  "(Cycles' principled BSDF differs from Mitsuba's)")

    if not args.no_profile:
        profile_fixed_cost(scene, args, settings)
    print(f"\nload average {load_before:.2f} at start, {load_after:.2f} after the timed part (2 cores: above "
          "~2 means other processes competed; see cpu/wall per keypoint)")


if __name__ == "__main__":
    main()
