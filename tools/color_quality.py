"""Quality mode of tools/bench_color.py: hybridgen's default color vs Blender Cycles at BlenderProc 2.8's
defaults, each scored against its own converged reference.

Run: .venv/bin/python tools/bench_color.py --quality [--res 320x240] [--reference-spp 4096] [--scenes a,b]

Scenes (built here from pybullet_data meshes, primitives and generated textures; one keypoint each):
- ``tabletop``: textured duck, bunny, football and a glossy (roughness 0.2) mug-like cylinder on a floor, one
  point light (the issue's scene);
- ``materials``: glossy, metallic, glass and emissive spheres on a floor, one point light;
- ``window_room``: a closed room with a window, a checker-textured floor and wall texture, lit by a sun and
  a sky (world color) through the window only;
- ``hdri_tabletop``: objects on a floor under a generated HDRI (sky gradient with a small, bright sun).

For each scene: hybridgen's defaults (``PathTraceSettings()`` + denoising, as ``renderer.RgbRenderer``
with no color options: stratified samples, Blackman-Harris 1.5 px pixel filter, adaptive 64..1024 spp at
noise threshold 0.01 in Cycles' meaning, indirect clamp 10, filter glossy 1.0, principled lobes sampled by
albedo, a constant world left to BSDF sampling, Cycles' roulette, 3 bounces for every lobe, OIDN; with
``--blenderproc-lobes`` glossy and transmission bounces 0 as Cycles renders at BlenderProc's defaults)
timed from scene load to the finished sRGB frame (scene translation, kernel compilation with a warm cache,
raster guides, render, denoise) in this process; its reference is the same estimator at a fixed
``--reference-spp`` without denoising (and once more without the clamp, to measure the clamp's bias).
Cycles (pip ``bpy`` in ``.venv-bpy``) renders with BlenderProc's defaults (``mode: blenderproc`` in
tools/cycles_render.py; its render time only, scene sync excluded) and its reference at the same spp
with ``mode: reference``. PSNR is computed on the 8-bit sRGB images (the ``colors`` users get).
Side-by-side PNGs (hybridgen | its reference | Cycles | its reference) go to ``--out``.

The machine is shared: times are wall-clock under whatever load there is; hybridgen and Cycles alternate
scene by scene.
"""
from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

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
    import hybridgen as hg

    scene = tabletop(width, height)
    scene.lights.clear()
    scene.world.hdri_path = str(sky_hdri(workdir / "sky.exr"))
    scene.world.strength, scene.world.hdri_rotation = 1.0, 0.3
    return scene


SCENES = ("tabletop", "materials", "window_room", "hdri_tabletop")


def build(name: str, width: int, height: int, workdir: Path) -> Any:
    if name == "hdri_tabletop":
        return hdri_tabletop(width, height, workdir)
    return {"tabletop": tabletop, "materials": materials, "window_room": window_room}[name](width, height)


# ------------------------------------------------------------------------------------------ scoring
def psnr(image: np.ndarray, reference: np.ndarray) -> float:
    """PSNR (dB) of two 8-bit sRGB images."""
    mse = float(np.mean((image.astype(np.float64) - reference.astype(np.float64)) ** 2))
    return float("inf") if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)


BLENDERPROC_LOBES = {"glossy_bounces": 0, "transmission_bounces": 0}
"""``--blenderproc-lobes``: BlenderProc's per-lobe limits (hybridgen's default is max_bounces for every lobe),
so that hybridgen estimates the same light paths as Cycles at BlenderProc's defaults."""
LOBES: dict[str, int] = {}


def hybridgen_default(scene: Any, seed: int,
                      threshold: float | None = None) -> tuple[np.ndarray, float, float, float]:
    """sRGB frame with hybridgen's defaults (``threshold`` overrides the noise threshold, for tuning), seconds
    from scene load to the frame (wall clock, and CPU time of this process's threads), mean samples per
    pixel."""
    from hybridgen.render.path_trace import PathTraceSettings
    from hybridgen.render.render_color import ColorProducer

    start, cpu = time.perf_counter(), time.process_time()
    producer = ColorProducer(scene, PathTraceSettings(noise_threshold=threshold, **LOBES), seed=seed, denoise=True,
                             sample_counts=True)
    frame = producer.produce(0, scene.camera.keypoints[0])
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    producer.close()
    return frame["colors"], seconds, float(frame["sample_counts"].mean()), cpu


def hybridgen_reference(scene: Any, spp: int, clamp: float) -> tuple[np.ndarray, float]:
    from hybridgen.render.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.tonemap import to_srgb8

    start = time.perf_counter()
    view = PathTraceView(scene, PathTraceSettings(samples=spp, clamp_indirect=clamp, **LOBES))
    image = view.render(scene.camera.keypoints[0], seed=12345)
    return to_srgb8(image), time.perf_counter() - start


def _read_png(path: Path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


def run_quality(args: Any, bpy_python: Path | None) -> list[dict[str, Any]]:
    from PIL import Image

    from bench_color import CyclesWorker, export_for_cycles

    width, height = (int(v) for v in args.res.split("x"))
    LOBES.clear()
    LOBES.update(BLENDERPROC_LOBES if args.blenderproc_lobes else {})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    names = args.scenes.split(",") if args.scenes else list(SCENES)
    for name in names:
        scene = build(name, width, height, out)
        row: dict[str, Any] = {"scene": name}
        ref, row["hg_ref_s"] = hybridgen_reference(scene, args.reference_spp, 10.0)
        ref_unclamped, _ = hybridgen_reference(scene, args.reference_spp, 0.0)
        image, row["hg_s"], row["hg_mean_spp"], row["hg_cpu_s"] = hybridgen_default(scene, seed=1,
                                                                                    threshold=args.hg_threshold)
        row["hg_psnr"] = psnr(image, ref)
        for threshold in args.try_thresholds:  # tuning: other thresholds, same reference
            other, seconds, spp, cpu = hybridgen_default(scene, seed=1, threshold=threshold)
            row[f"hg_{threshold}"] = {"psnr": psnr(other, ref), "s": seconds, "spp": spp, "cpu_s": cpu}
        row["hg_psnr_vs_unclamped_ref"] = psnr(image, ref_unclamped)
        row["clamp_bias_psnr"] = psnr(ref, ref_unclamped)
        row["clamp_bias_mean"] = float(ref.astype(float).mean() - ref_unclamped.astype(float).mean())
        panels = [image, ref]
        if bpy_python is not None:
            npz = out / f"{name}.npz"
            export_for_cycles(scene, npz, 1024, 3, 0)
            worker = CyclesWorker(bpy_python, npz)
            try:
                cycles_png, cycles_ref_png = out / f"{name}_cycles.png", out / f"{name}_cycles_ref.png"
                answer = worker.render(0, False, 1, cycles_png, mode="blenderproc")
                row["cycles_s"], row["cycles_cpu_s"] = answer["seconds"], answer["cpu_s"]
                answer = worker.render(0, False, 12345, cycles_ref_png, mode="reference", spp=args.reference_spp)
                row["cycles_ref_s"] = answer["seconds"]
            finally:
                worker.close()
            cycles, cycles_ref = _read_png(cycles_png), _read_png(cycles_ref_png)
            row["cycles_psnr"] = psnr(cycles, cycles_ref)
            panels += [cycles, cycles_ref]
        Image.fromarray(np.concatenate(panels, axis=1)).save(out / f"{name}_side_by_side.png")
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def print_table(rows: list[dict[str, Any]], reference_spp: int) -> None:
    print(f"\nPSNR (dB, 8-bit sRGB) against each engine's own {reference_spp}-spp reference; time in s (wall; "
          "CPU = CPU time of the engine's threads, steadier on a loaded machine)")
    print(f"{'scene':15} {'hybridgen':>10} {'time':>7} {'CPU':>6} {'spp':>6} {'Cycles BP':>10} {'time':>7} {'CPU':>6} "
          f"{'wall ratio':>10} {'CPU ratio':>9} {'clamp bias':>10}")
    nan = float("nan")
    for r in rows:
        ratio = r["hg_s"] / r["cycles_s"] if r.get("cycles_s") else nan
        cpu_ratio = r["hg_cpu_s"] / r["cycles_cpu_s"] if r.get("cycles_cpu_s") else nan
        print(f"{r['scene']:15} {r['hg_psnr']:10.1f} {r['hg_s']:7.2f} {r['hg_cpu_s']:6.2f} {r['hg_mean_spp']:6.0f} "
              f"{r.get('cycles_psnr', nan):10.1f} {r.get('cycles_s', nan):7.2f} {r.get('cycles_cpu_s', nan):6.2f} "
              f"{ratio:10.2f} {cpu_ratio:9.2f} {r['clamp_bias_psnr']:10.1f}")
    print("clamp bias: PSNR of hybridgen's clamped reference against its unclamped one (higher = less bias)")
