"""Quality mode of tools/bench_color.py: hybridgen's default color vs Blender Cycles at BlenderProc 2.8's
defaults, each scored against its own converged reference.

Scenes (built here from pybullet_data meshes, primitives and generated textures; one keypoint each):
- ``tabletop``: textured duck, bunny, football and a glossy (roughness 0.2) mug-like cylinder on a floor, one
  point light (the issue's scene);
- ``materials``: glossy, metallic, glass and emissive spheres on a floor, one point light;
- ``window_room``: a closed room with a window, a checker-textured floor and wall texture, lit by a sun and
  a sky (world color) through the window only;
- ``hdri_tabletop``: objects on a floor under a generated HDRI (sky gradient with a small, bright sun).

Run: .venv/bin/python tools/bench_color.py --quality   (the issue's settings: 320x240, 4096-spp references)
     .venv/bin/python tools/bench_color.py --quality [--res 160x120] [--reference-spp 2048] [--scenes a,b]
     nice -n 10 .venv/bin/python tools/bench_color.py --quality --precompute cycles   (only fill the cache)

For each scene: hybridgen's defaults (``PathTraceSettings()`` + denoising, as ``renderer.RgbRenderer``
with no color options: stratified samples, Blackman-Harris 1.5 px pixel filter, adaptive 64..768 spp at
noise threshold 0.005 in Cycles' meaning, indirect clamp 10, filter glossy 1.0, principled lobes sampled by
albedo, a constant world left to BSDF sampling, Cycles' roulette, 3 bounces for every lobe, OIDN; with
``--blenderproc-lobes`` glossy and transmission bounces 0 as Cycles renders at BlenderProc's defaults, with
``--lobes no-refractive-caustics`` ``caustics_refractive: false``),
timed as the issue asks: the WHOLE process (tools/default_color_process.py: Python's start, ``import
hybridgen``, the scene built from its mesh files, Mitsuba, kernels, raster guides, render, denoise, the PNG
written), wall clock from spawn to exit and CPU from the child's rusage. The first run of each scene gets
fresh Dr.Jit kernel and hybridgen mesh caches (a new user: reported as "cold"); the timed runs
(``--warm-runs``, median) reuse them, as a user's runs after the first. The in-process time of
``render_color`` is reported beside it. hybridgen's reference is the same estimator at a fixed
``--reference-spp`` without denoising (and once more without the clamp, to measure the clamp's bias).
Both engines use ``--threads`` CPU threads (2, the issue's). Cycles (pip ``bpy`` in ``.venv-bpy``) renders
with BlenderProc's defaults (``mode: blenderproc`` in tools/cycles_render.py), timed as its render only
(``bpy.ops.render.render``: Cycles' scene sync, BVH, render and denoise; building the Blender scene from the
export is not counted), and its reference at the same spp with ``mode: reference``. PSNR is computed on the
8-bit sRGB images (the ``colors`` users get). References come from the on-disk cache of
tools/reference_cache.py when their key matches (``--reference-cache PATH|off``). Side-by-side PNGs (hybridgen
| its reference | Cycles | its reference) and the rows as JSON go to ``--out``.

The machine is shared: times are wall-clock under whatever load there is (the load average is printed at
start and end; CPU seconds are steadier). Cycles' timed render runs once beside each warm hybridgen run (after it
in even pairs, before it in odd ones: ABBA), and the table's ratios are the medians of the pairs' ratios, so a
drift in the machine's speed over minutes cancels.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

import numpy as np
from default_color_process import LOBES
from reference_cache import ReferenceCache, cache_root, code_digest, estimator_digest, scene_digest

REPO = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------------------------------------ scenes
def _camera(scene: Any, width: int, height: int, location: list[float], target: list[float], fov: float) -> None:
    import hybridgen as hg

    scene.camera.intrinsics = hg.Intrinsics.from_fov(fov, width, height, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at(location, target))


def _floor(size: float = 6.0, albedo: float = 0.6) -> Any:
    import hybridgen as hg

    floor = hg.make_primitive("plane", size, name="floor", category_id=1, color=(albedo, albedo, albedo))
    floor.material.specular = 0.0
    return floor


def _pybullet_mesh(file: str, name: str, category_id: int, size: float, xy: tuple[float, float],
                   yaw: float = 0.0) -> list[Any]:
    """A pybullet_data mesh scaled to ``size`` m (largest extent), turned by ``yaw`` about +Z and standing
    on the floor at ``xy``."""
    import pybullet_data

    import hybridgen as hg

    objects = hg.load_objects(Path(pybullet_data.getDataPath()) / file, name=name, category_id=category_id)
    vertices = np.concatenate([obj.world_vertices() for obj in objects])
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    centre = np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]])
    move = hg.object_pose([xy[0], xy[1], 0.0], [0.0, 0.0, yaw]) @ np.diag([size / np.max(high - low)] * 3 + [1.0])
    move = move @ hg.object_pose((-centre).tolist())
    for obj in objects:
        obj.local2world = move @ obj.local2world
    return objects


def checker(size: int = 256, squares: int = 8, a: tuple[int, ...] = (200, 190, 170),
            b: tuple[int, ...] = (70, 60, 50)) -> np.ndarray:
    """An sRGB uint8 checkerboard texture (size x size x 3)."""
    cells = (np.indices((size, size)) * squares // size).sum(axis=0) % 2
    return np.where(cells[..., None] == 0, np.array(a, np.uint8), np.array(b, np.uint8)).astype(np.uint8)


def _planar_uvs(obj: Any, repeat: float = 1.0) -> None:
    """UVs from the object's local x/y (a plane primitive spans -size/2..size/2)."""
    xy = obj.vertices[:, :2]
    span = np.ptp(xy, axis=0)
    obj.uvs = ((xy - xy.min(axis=0)) / np.where(span > 0, span, 1.0) * repeat).astype(np.float32)


def tabletop(width: int, height: int) -> Any:
    import hybridgen as hg

    scene = hg.Scene()
    scene.add(_floor())
    for obj in _pybullet_mesh("duck.obj", "duck", 2, 0.3, (-0.35, 0.1), 0.5):
        scene.add(obj)
    for obj in _pybullet_mesh("bunny.obj", "bunny", 3, 0.3, (0.3, 0.25)):
        obj.material.specular = 0.0
        scene.add(obj)
    for obj in _pybullet_mesh("soccerball.obj", "football", 4, 0.22, (0.35, -0.3)):
        scene.add(obj)
    mug = hg.make_primitive("cylinder", 0.22, name="mug", category_id=5, color=(0.75, 0.2, 0.15),
                            local2world=hg.object_pose([-0.05, -0.35, 0.11]))
    mug.material.roughness, mug.material.specular = 0.2, 0.5
    scene.add(mug)
    scene.add_light(hg.Light("lamp", "POINT", energy=150.0, local2world=hg.object_pose([0.6, -0.8, 1.6])))
    _camera(scene, width, height, [1.1, -1.3, 0.9], [0.0, 0.0, 0.1], 0.9)
    return scene


def materials(width: int, height: int) -> Any:
    import hybridgen as hg

    scene = hg.Scene()
    scene.add(_floor())
    spheres = [("glossy", (0.1, 0.3, 0.8), dict(roughness=0.2, specular=0.5)),
               ("metal", (0.9, 0.7, 0.4), dict(metallic=1.0, roughness=0.1)),
               ("glass", (1.0, 1.0, 1.0), dict(transmission=1.0, roughness=0.0, ior=1.5)),
               ("emitter", (1.0, 0.6, 0.3), dict(emission=(1.0, 0.6, 0.3), emission_strength=4.0, specular=0.0))]
    for index, (name, color, values) in enumerate(spheres):
        ball = hg.make_primitive("sphere", 0.3, name=name, category_id=index + 2, color=color,
                                 local2world=hg.object_pose([-0.55 + 0.37 * index, 0.0, 0.15]))
        for key, value in values.items():
            setattr(ball.material, key, value)
        scene.add(ball)
    scene.add_light(hg.Light("lamp", "POINT", energy=120.0, local2world=hg.object_pose([0.4, -0.9, 1.4])))
    _camera(scene, width, height, [0.2, -1.6, 0.7], [0.0, 0.0, 0.12], 0.8)
    return scene


def window_room(width: int, height: int) -> Any:
    """A 4 x 4 x 2.6 m room; the +y wall has a 1.2 x 1.0 m window; sun and sky shine in through it."""
    import hybridgen as hg

    scene = hg.Scene()
    floor = _floor(4.0, 0.8)
    floor.material.base_color_texture = checker()
    _planar_uvs(floor, repeat=2.0)
    scene.add(floor)
    half, top = 2.0, 2.6
    walls = [  # (name, size x, size y, pose): planes are z-up squares scaled into rectangles
        ("ceiling", 4.0, 4.0, hg.object_pose([0, 0, top], [math.pi, 0, 0])),
        ("wall_west", 4.0, top, hg.object_pose([-half, 0, top / 2], [0, math.pi / 2, 0])),
        ("wall_east", 4.0, top, hg.object_pose([half, 0, top / 2], [0, -math.pi / 2, 0])),
        ("wall_south", 4.0, top, hg.object_pose([0, -half, top / 2], [-math.pi / 2, 0, 0])),
        # the window wall (y = +2) around a hole x in [-0.6, 0.6], z in [0.9, 1.9]
        ("window_left", 1.4, top, hg.object_pose([-1.3, half, top / 2], [math.pi / 2, 0, 0])),
        ("window_right", 1.4, top, hg.object_pose([1.3, half, top / 2], [math.pi / 2, 0, 0])),
        ("window_below", 1.2, 0.9, hg.object_pose([0, half, 0.45], [math.pi / 2, 0, 0])),
        ("window_above", 1.2, 0.7, hg.object_pose([0, half, 2.25], [math.pi / 2, 0, 0])),
    ]
    for index, (name, sx, sy, pose) in enumerate(walls):
        wall = hg.make_primitive("plane", 1.0, name=name, category_id=10 + index, color=(0.75, 0.72, 0.68),
                                 local2world=pose @ np.diag([sx, sy, 1.0, 1.0]))
        wall.material.specular = 0.0
        if name == "wall_west":
            wall.material.base_color_texture = checker(128, 4, (180, 60, 50), (230, 220, 200))
            _planar_uvs(wall)
        scene.add(wall)
    table = hg.make_primitive("cube", 0.6, name="table", category_id=30, color=(0.5, 0.35, 0.2),
                              local2world=hg.object_pose([0.3, 0.4, 0.3]))
    table.material.roughness = 0.3
    scene.add(table)
    scene.world.color, scene.world.strength = (0.45, 0.6, 0.9), 1.0
    # sun from outside the window (+y), 35 degrees above the horizon, shining into the room along its -z
    scene.add_light(hg.Light("sun", "SUN", energy=4.0, local2world=hg.object_pose([0, 5, 4],
                                                                                 [-math.radians(55), 0, 0])))
    _camera(scene, width, height, [-1.5, -1.6, 1.5], [0.4, 1.0, 0.6], 1.3)
    return scene


def sky_hdri(path: Path, width: int = 256) -> Path:
    """An equirectangular float32 RGB EXR: a blue-to-white sky over a dark ground and a small sun, written
    with Mitsuba's Bitmap."""
    import mitsuba as mi

    height = width // 2
    theta = (np.arange(height) + 0.5) / height * math.pi  # 0 = zenith
    phi = (np.arange(width) + 0.5) / width * 2 * math.pi
    up = np.cos(theta)[:, None, None]
    sky = np.where(up > 0, 0.3 + 0.7 * np.array([0.4, 0.6, 1.0]) * np.maximum(up, 0.0) ** 0.4,
                   np.array([0.15, 0.13, 0.1]))
    image = np.broadcast_to(sky, (height, width, 3)).copy()
    sun_theta, sun_phi = math.radians(50), math.radians(120)
    d = np.stack([np.sin(theta)[:, None] * np.cos(phi)[None], np.sin(theta)[:, None] * np.sin(phi)[None],
                  np.broadcast_to(np.cos(theta)[:, None], (height, width))], axis=-1)
    s = np.array([math.sin(sun_theta) * math.cos(sun_phi), math.sin(sun_theta) * math.sin(sun_phi),
                  math.cos(sun_theta)])
    image[(d @ s) > math.cos(math.radians(3.0))] = [400.0, 380.0, 340.0]
    mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(path))
    return path


def hdri_tabletop(width: int, height: int, workdir: Path) -> Any:
    scene = tabletop(width, height)
    scene.lights.clear()
    scene.world.hdri_path = str(sky_hdri(workdir / "sky.exr"))
    scene.world.strength, scene.world.hdri_rotation = 1.0, 0.3
    return scene


SCENES = ("tabletop", "materials", "window_room", "hdri_tabletop")


def build(name: str, width: int, height: int, workdir: Path) -> Any:
    """Scene ``name`` (one of :data:`SCENES`) at ``width`` x ``height`` px; generated inputs go to ``workdir``."""
    if name == "hdri_tabletop":
        return hdri_tabletop(width, height, workdir)
    return {"tabletop": tabletop, "materials": materials, "window_room": window_room}[name](width, height)


# ------------------------------------------------------------------------------------------ scoring
def psnr(image: np.ndarray, reference: np.ndarray) -> float:
    """PSNR (dB) of two 8-bit sRGB images."""
    mse = float(np.mean((image.astype(np.float64) - reference.astype(np.float64)) ** 2))
    return float("inf") if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)


def _read_png(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


# -------------------------------------------------------------------------------------- references
REFERENCE_SEED = 12345
"""Seed of both engines' references (the measured renders use seed 1)."""
CLAMP = 10.0
"""hybridgen's default indirect clamp, the value its reference is rendered with (and 0 for the clamp bias)."""


def hybridgen_reference(scene: Any, spp: int, clamp: float,
                        lobes: dict[str, int] | None = None) -> tuple[np.ndarray, float]:
    """hybridgen's own estimator at a fixed ``spp`` (no adaptivity, no denoising) with indirect clamp ``clamp``
    (0: off) and per-lobe bounces ``lobes`` (default: hybridgen's): the sRGB frame and its wall seconds, in
    this process."""
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.tonemap import to_srgb8

    start = time.perf_counter()
    view = PathTraceView(scene, PathTraceSettings(samples=spp, clamp_indirect=clamp, **(lobes or {})))
    image = view.render(scene.camera.keypoints[0], seed=REFERENCE_SEED)
    return to_srgb8(image), time.perf_counter() - start


def bpy_version(python: Path) -> str:
    """The ``bpy`` package version of the bpy venv's ``python`` (without importing Blender)."""
    done = subprocess.run([str(python), "-c", "import importlib.metadata as m; print(m.version('bpy'))"],
                          capture_output=True, text=True, check=True)
    return done.stdout.strip()


class CyclesSession:
    """tools/cycles_render.py on one exported scene, started on first use (cached references need none)."""

    def __init__(self, python: Path, npz: Path) -> None:
        self.python, self.npz = python, npz
        self.worker: Any = None

    def render(self, seed: int, png: Path, **request: Any) -> dict[str, Any]:
        """Keypoint 0 rendered into ``png``; ``request``: ``mode``, ``spp`` (tools/cycles_render.py)."""
        from bench_color import CyclesWorker

        if self.worker is None:
            self.worker = CyclesWorker(self.python, self.npz)
        return self.worker.render(0, False, seed, png, **request)

    def close(self) -> None:
        if self.worker is not None:
            self.worker.close()


class References:
    """Both engines' ``spp`` references of the scenes at ``resolution`` from the :class:`ReferenceCache`, or
    rendered and stored (keys: tools/reference_cache.py)."""

    def __init__(self, cache: ReferenceCache, spp: int, resolution: str, lobes: str, bpy_python: Path | None,
                 workdir: Path) -> None:
        from importlib.metadata import version

        self.cache, self.spp, self.resolution, self.lobes, self.workdir = cache, spp, resolution, lobes, workdir
        self.hybridgen_code = {"estimator": estimator_digest(), "mitsuba": version("mitsuba"),
                               "drjit": version("drjit")}
        self.cycles_code = {"bpy": bpy_version(bpy_python) if bpy_python else None,
                            "cycles_render": code_digest(REPO / "tools" / "cycles_render.py")}

    def _key(self, name: str, content: str) -> dict[str, Any]:
        return {"scene": name, "resolution": self.resolution, "spp": self.spp, "seed": REFERENCE_SEED,
                "content": content}

    def hybridgen(self, name: str, scene: Any, content: str, clamp: float) -> tuple[np.ndarray, dict[str, Any]]:
        """hybridgen's reference with indirect clamp ``clamp`` (and the record: seconds, cached)."""
        key = {**self._key(name, content), "clamp_indirect": clamp, "lobes": self.lobes, **self.hybridgen_code}

        def render() -> tuple[np.ndarray, dict[str, Any]]:
            image, seconds = hybridgen_reference(scene, self.spp, clamp, LOBES[self.lobes])
            return image, {"seconds": seconds}

        return self.cache.fetch("hybridgen", key, render)

    def cycles(self, name: str, content: str, session: CyclesSession) -> tuple[np.ndarray, dict[str, Any]]:
        """Cycles' reference (BlenderProc's estimator at a fixed spp, ``mode: reference``) and its record."""
        key = {**self._key(name, content), "mode": "reference", "light_tree": False, **self.cycles_code}

        def render() -> tuple[np.ndarray, dict[str, Any]]:
            png = self.workdir / f"{name}_cycles_ref.png"
            answer = session.render(REFERENCE_SEED, png, mode="reference", spp=self.spp)
            return _read_png(png), {"seconds": answer["seconds"], "cpu_s": answer["cpu_s"],
                                    "blender": session.worker.hello["blender"]}

        return self.cache.fetch("cycles", key, render)


# ------------------------------------------------------------------------------------------ the host
@lru_cache(maxsize=None)
def host_cpu() -> dict[str, Any]:
    """The CPU the timings come from: its model name and widest vector instruction set, and the float32 lanes
    Dr.Jit's LLVM backend generates for it (16 with AVX-512, 8 with AVX/AVX2, 4 otherwise: its native width).
    Ratios to Cycles depend on it: hybridgen's path tracer is Dr.Jit-vectorized, Cycles' is not (its Embree is)."""
    model, flags = "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and model == "unknown":
                model = value.strip()
            elif key.strip() == "flags" and not flags:
                flags = set(value.split())
    except OSError:
        pass
    isa = "avx512f" if "avx512f" in flags else "avx2" if "avx2" in flags else "avx" if "avx" in flags else "sse"
    return {"model": model, "isa": isa, "drjit_llvm_lanes": {"avx512f": 16, "avx2": 8, "avx": 8}.get(isa, 4)}


# ------------------------------------------------------------------------------ whole-process timing
@dataclass(frozen=True)
class Finished:
    """A finished child process: its last JSON line, wall seconds from spawn to reaping, and CPU seconds
    (user + system, from its rusage: every thread, and its own children once it waited for them)."""

    report: dict[str, Any]
    wall: float
    cpu: float


def run_timed(command: list[str], env: dict[str, str]) -> Finished:
    """Runs ``command`` to its end; raises RuntimeError with its output's tail if it fails."""
    with tempfile.TemporaryFile() as output:
        start = time.perf_counter()
        child = subprocess.Popen(command, stdout=output, stderr=subprocess.STDOUT, env=env)
        _, status, usage = os.wait4(child.pid, 0)  # this child's own rusage (RUSAGE_CHILDREN mixes in others)
        wall = time.perf_counter() - start
        child.returncode = os.waitstatus_to_exitcode(status)
        output.seek(0)
        lines = output.read().decode(errors="replace").strip().splitlines()
    if child.returncode != 0:
        raise RuntimeError(f"`{' '.join(command)}` failed (exit {child.returncode}):\n  " + "\n  ".join(lines[-8:]))
    report = next(json.loads(line) for line in reversed(lines) if line.startswith("{"))
    return Finished(report, wall, usage.ru_utime + usage.ru_stime)


class DefaultRuns:
    """hybridgen's default render of one scene as whole processes (tools/default_color_process.py) that share
    fresh caches (Dr.Jit's kernels, hybridgen's parsed meshes): the first run is a new user's (cold), the
    next ones a returning user's (warm). Dr.Jit runs ``threads`` threads (``$HYBRIDGEN_THREADS``). Byte-compiled
    sources are used and written as by an installed package (``PYTHONDONTWRITEBYTECODE`` is dropped)."""

    def __init__(self, name: str, resolution: str, workdir: Path, lobes: str, threads: int) -> None:
        self.name, self.resolution, self.workdir, self.lobes = name, resolution, workdir, lobes
        self.caches = Path(tempfile.mkdtemp(prefix=f"{name}-caches-", dir=workdir))
        self.env = {**os.environ, "DRJIT_CACHE_DIR": str(self.caches / "drjit"),
                    "HYBRIDGEN_CACHE_DIR": str(self.caches / "hybridgen"), "HYBRIDGEN_THREADS": str(threads)}
        self.env.pop("PYTHONDONTWRITEBYTECODE", None)

    def run(self, png: Path, threshold: float | None = None, max_samples: int | None = None) -> dict[str, Any]:
        """One process (hybridgen's defaults but for a noise ``threshold`` and a ``max_samples`` when given):
        wall and CPU seconds, mean spp, and its phases (s): ``startup`` (spawn to the script's
        first line), ``import`` (hybridgen), ``build`` (the scene), ``render`` (render_color: scene translation,
        kernels, raster guides, render, denoise - the in-process time), ``write`` (the PNG), ``exit``."""
        command = [sys.executable, str(REPO / "tools" / "default_color_process.py"), self.name, self.resolution,
                   str(png), str(self.workdir), "--lobes", self.lobes]
        command += ["--threshold", str(threshold)] if threshold is not None else []
        command += ["--max-samples", str(max_samples)] if max_samples is not None else []
        spawned = time.time()
        finished = run_timed(command, self.env)
        r = finished.report
        return {"wall": finished.wall, "cpu": finished.cpu, "mean_spp": r["mean_spp"],
                "startup": r["started"] - spawned, "import": r["imported"] - r["started"],
                "build": r["built"] - r["imported"], "render": r["rendered"] - r["built"],
                "write": r["written"] - r["rendered"], "exit": finished.wall - (r["written"] - spawned)}

    def close(self) -> None:
        shutil.rmtree(self.caches, ignore_errors=True)


# ----------------------------------------------------------------------------------------- scoring
PHASES = ("startup", "import", "build", "render", "write", "exit")
"""The phases of a timed hybridgen process (:meth:`DefaultRuns.run`)."""


def lobes_name(args: Any) -> str:
    """The name of default_color_process.LOBES' entry the benchmark renders hybridgen with: ``--lobes``, or
    ``blenderproc`` for ``--blenderproc-lobes``."""
    return args.lobes if args.lobes else ("blenderproc" if args.blenderproc_lobes else "default")


def time_hybridgen(name: str, resolution: str, workdir: Path, args: Any, reference: np.ndarray,
                   row: dict[str, Any], partner: Callable[[], None] | None = None) -> np.ndarray:
    """Fills ``row`` with hybridgen's whole-process numbers (one cold run, ``args.warm_runs`` warm ones:
    medians, and each warm run's times) and PSNR; returns its frame. ``partner`` (Cycles' timed render) runs once
    beside each warm run - after it in even pairs, before it in odd ones - so each pair of timings sees the same
    state of the shared machine and a drift in its speed cancels in the pair's ratio."""
    runs = DefaultRuns(name, resolution, workdir, lobes_name(args), args.threads)
    try:
        cold_png, png = workdir / f"{name}_hybridgen_cold.png", workdir / f"{name}_hybridgen.png"
        cold = runs.run(cold_png, args.hg_threshold, args.hg_max_samples)
        warm = []
        for pair in range(max(1, args.warm_runs)):
            if partner is not None and pair % 2 == 1:
                partner()
            warm.append(runs.run(png, args.hg_threshold, args.hg_max_samples))
            if partner is not None and pair % 2 == 0:
                partner()
        for threshold in args.try_thresholds:  # tuning: other thresholds, same reference, warm
            other_png = workdir / f"{name}_hybridgen_{threshold}.png"
            other = runs.run(other_png, threshold, args.hg_max_samples)
            row[f"hg_{threshold}"] = {"psnr": psnr(_read_png(other_png), reference), "s": other["wall"],
                                      "spp": other["mean_spp"], "cpu_s": other["cpu"]}
    finally:
        runs.close()
    image = _read_png(png)
    typical = sorted(warm, key=lambda run: run["wall"])[(len(warm) - 1) // 2]
    row.update(hg_psnr=psnr(image, reference), hg_mean_spp=typical["mean_spp"],
               hg_s=statistics.median(run["wall"] for run in warm),
               hg_cpu_s=statistics.median(run["cpu"] for run in warm), hg_cold_s=cold["wall"],
               hg_cold_cpu_s=cold["cpu"], hg_inprocess_s=typical["render"],
               hg_warm_s=[run["wall"] for run in warm], hg_warm_cpu_s=[run["cpu"] for run in warm],
               hg_phases={key: round(typical[key], 3) for key in PHASES},
               hg_cold_phases={key: round(cold[key], 3) for key in PHASES},
               hg_same_bytes_cold_warm=bool(np.array_equal(_read_png(cold_png), image)))
    return image


class CyclesTimes:
    """Cycles' timed renders at BlenderProc's defaults (``bpy.ops.render.render`` alone), one per call, each
    into the same PNG (the same seed: the same frame)."""

    def __init__(self, name: str, session: CyclesSession, workdir: Path) -> None:
        self.name, self.session, self.png = name, session, workdir / f"{name}_cycles.png"
        self.answers: list[dict[str, Any]] = []

    def __call__(self) -> None:
        self.answers.append(self.session.render(1, self.png, mode="blenderproc"))

    def finish(self, workdir: Path, row: dict[str, Any]) -> np.ndarray:
        """After :func:`time_hybridgen` ran one render per warm run: fills ``row`` with the renders' median times,
        each render's times and the per-pair ratios to hybridgen's warm runs (``row['hg_warm_s']``, in the same
        order) with their medians, which the table reports; returns Cycles' frame."""
        walls, cpus = [a["seconds"] for a in self.answers], [a["cpu_s"] for a in self.answers]
        assert len(walls) == len(row["hg_warm_s"]), "one Cycles render per warm hybridgen run"
        walls_ratio = [hg / cy for hg, cy in zip(row["hg_warm_s"], walls)]
        cpus_ratio = [hg / cy for hg, cy in zip(row["hg_warm_cpu_s"], cpus)]
        row.update(cycles_s=statistics.median(walls), cycles_cpu_s=statistics.median(cpus), cycles_runs_s=walls,
                   cycles_runs_cpu_s=cpus, pair_wall_ratios=walls_ratio, pair_cpu_ratios=cpus_ratio,
                   wall_ratio=statistics.median(walls_ratio), cpu_ratio=statistics.median(cpus_ratio))
        # Its samples per pixel from the same render again with Cycles' Debug Sample Count pass (untimed: the pass
        # is not part of BlenderProc's defaults), so the two engines' samples can be compared, not only their times.
        counts = workdir / f"{self.name}_cycles_counts.npy"
        self.session.render(1, workdir / f"{self.name}_cycles_counted.png", mode="blenderproc",
                            sample_counts=str(counts))
        row["cycles_mean_spp"] = float(np.load(counts).mean())
        return _read_png(self.png)


def quality_row(name: str, scene: Any, content: str, refs: References, session: CyclesSession | None,
                args: Any, workdir: Path, out: Path) -> dict[str, Any]:
    """One scene's row: both engines' defaults timed in interleaved pairs (:func:`time_hybridgen`) and scored
    against their references; the side-by-side PNG (hybridgen | its reference | Cycles | its reference)."""
    from PIL import Image

    resolution = refs.resolution
    row: dict[str, Any] = {"scene": name, "resolution": resolution, "reference_spp": refs.spp, "lobes": refs.lobes,
                           "hg_threshold": args.hg_threshold, "hg_max_samples": args.hg_max_samples,
                           "cpu": host_cpu()}
    ref, record = refs.hybridgen(name, scene, content, CLAMP)
    ref_unclamped, _ = refs.hybridgen(name, scene, content, 0.0)
    row["hg_ref_s"], row["hg_ref_cached"] = record["seconds"], record["cached"]
    cycles_times = CyclesTimes(name, session, workdir) if session is not None else None
    image = time_hybridgen(name, resolution, workdir, args, ref, row, cycles_times)
    row["hg_psnr_vs_unclamped_ref"] = psnr(image, ref_unclamped)
    row["clamp_bias_psnr"] = psnr(ref, ref_unclamped)
    row["clamp_bias_mean"] = float(ref.astype(float).mean() - ref_unclamped.astype(float).mean())
    panels = [image, ref]
    if cycles_times is not None:
        cycles = cycles_times.finish(workdir, row)
        cycles_ref, record = refs.cycles(name, content, cycles_times.session)
        row["cycles_psnr"] = psnr(cycles, cycles_ref)
        row["cycles_ref_s"], row["cycles_ref_cached"] = record["seconds"], record["cached"]
        panels += [cycles, cycles_ref]
    Image.fromarray(np.concatenate(panels, axis=1)).save(out / f"{name}_side_by_side.png")
    return row


def precompute(name: str, scene: Any, content: str, refs: References, session: CyclesSession | None,
               engines: str) -> None:
    """Renders (or finds) the references of ``engines`` ("cycles", "hybridgen" or "all") and says which."""
    found: list[tuple[str, dict[str, Any]]] = []
    if engines in ("hybridgen", "all"):
        found += [(f"hybridgen clamp {clamp:g}", refs.hybridgen(name, scene, content, clamp)[1])
                  for clamp in (CLAMP, 0.0)]
    if engines in ("cycles", "all") and session is not None:
        found.append(("Cycles", refs.cycles(name, content, session)[1]))
    for what, record in found:
        state = "cached" if record["cached"] else f"rendered in {record['seconds']:.1f} s"
        print(f"{name} {refs.resolution} {refs.spp} spp, {what}: {state}", flush=True)


def run_quality(args: Any, bpy_python: Path | None) -> list[dict[str, Any]]:
    """The quality benchmark (or, with ``args.precompute``, only its references): one row per scene."""
    from bench_color import export_for_cycles

    width, height = (int(v) for v in args.res.lower().split("x"))
    resolution = f"{width}x{height}"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    workdir = Path(tempfile.mkdtemp(prefix="bench_color_quality_"))  # private: concurrent runs share --out
    cache = ReferenceCache(cache_root(args.reference_cache))
    refs = References(cache, args.reference_spp, resolution, lobes_name(args), bpy_python,
                      workdir)
    load = os.getloadavg()
    print(f"{resolution}, references {args.reference_spp} spp, {args.threads} threads per engine, reference cache "
          f"{cache.root if cache.root else 'off'}; {os.cpu_count()} cores, load average {load[0]:.2f} "
          f"{load[1]:.2f} {load[2]:.2f} at start", flush=True)
    cpu = host_cpu()
    print(f"CPU: {cpu['model']}, {cpu['isa']} (Dr.Jit LLVM {cpu['drjit_llvm_lanes']} lanes)", flush=True)
    rows = []
    try:
        for name in args.scenes.split(",") if args.scenes else SCENES:
            scene = build(name, width, height, workdir)
            npz = workdir / f"{name}.npz"
            export_for_cycles(scene, npz, 1024, 3, 0, threads=args.threads)
            content = scene_digest(npz)
            session = CyclesSession(bpy_python, npz) if bpy_python is not None else None
            try:
                if args.precompute:
                    precompute(name, scene, content, refs, session, args.precompute)
                    continue
                row = quality_row(name, scene, content, refs, session, args, workdir, out)
            finally:
                if session is not None:
                    session.close()
            rows.append(row)
            print(json.dumps(row), flush=True)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} at the end", flush=True)
    if rows:
        (out / f"quality_{resolution}_{args.reference_spp}spp.json").write_text(json.dumps(rows, indent=1))
    return rows


def _row_name(row: dict[str, Any]) -> str:
    """The scene's name in the table, with hybridgen's settings where they are not its defaults (rows of older
    JSON files have no such keys)."""
    notes = [f"{row['lobes']} lobes"] if row.get("lobes", "default") != "default" else []
    notes += [f"threshold {row['hg_threshold']:g}"] if row.get("hg_threshold") is not None else []
    notes += [f"at most {row['hg_max_samples']} spp"] if row.get("hg_max_samples") is not None else []
    return row["scene"] + (f" ({', '.join(notes)})" if notes else "")


def print_table(rows: list[dict[str, Any]], reference_spp: int) -> None:
    """The rows as a Markdown table (goal: hybridgen's PSNR >= Cycles' and time ratio <= 0.5)."""
    if not rows:
        return
    nan = float("nan")
    print(f"\nPSNR (dB, 8-bit sRGB) against each engine's own {reference_spp}-spp reference at "
          f"{rows[0]['resolution']}. hybridgen: the whole process (median of warm runs; cold = fresh Dr.Jit kernel "
          "and mesh caches; in-proc = render_color alone); Cycles: its render only, at BlenderProc's defaults "
          "(median of as many renders, each paired with a warm run). CPU = user + system s of every thread. Ratio = "
          "hybridgen / Cycles, the median of the pairs' ratios.\n")
    print("| scene | hybridgen dB (mean spp) | hg wall s | hg CPU s | hg cold wall s | hg in-proc s | "
          "Cycles dB (mean spp) | Cycles wall s | Cycles CPU s | wall ratio | CPU ratio | goal (wall / CPU) | "
          "clamp bias dB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        # the median of the interleaved pairs' ratios; rows of older JSON files: the ratio of the medians
        wall_ratio = r.get("wall_ratio", r["hg_s"] / r["cycles_s"] if r.get("cycles_s") else nan)
        cpu_ratio = r.get("cpu_ratio", r["hg_cpu_s"] / r["cycles_cpu_s"] if r.get("cycles_cpu_s") else nan)
        clean = r["hg_psnr"] >= r.get("cycles_psnr", nan)
        goal = " / ".join("yes" if clean and ratio <= 0.5 else "no" for ratio in (wall_ratio, cpu_ratio))
        print(f"| {_row_name(r)} | {r['hg_psnr']:.1f} ({r['hg_mean_spp']:.0f}) | {r['hg_s']:.2f} | "
              f"{r['hg_cpu_s']:.2f} | {r['hg_cold_s']:.2f} | {r['hg_inprocess_s']:.2f} | "
              f"{r.get('cycles_psnr', nan):.1f} ({r.get('cycles_mean_spp', nan):.0f}) | {r.get('cycles_s', nan):.2f} | "
              f"{r.get('cycles_cpu_s', nan):.2f} | "
              f"{wall_ratio:.2f} | {cpu_ratio:.2f} | {goal} | {r['clamp_bias_psnr']:.1f} |")
    print("\nclamp bias: PSNR of hybridgen's clamped reference against its unclamped one (higher = less bias; inf = "
          "none). Warm-run phases (s) per scene, startup / import / build / render / write / exit:")
    for r in rows:
        print(f"  {r['scene']}: " + " / ".join(f"{r['hg_phases'][k]:.2f}" for k in PHASES)
              + " (cold: " + " / ".join(f"{r['hg_cold_phases'][k]:.2f}" for k in PHASES) + ")")
