"""hybridgen's color against Blender 4.2's Cycles, object by object, on a sweep of Principled materials.

Run: .venv/bin/python tools/principled_vs_cycles.py [--res 360x240] [--spp 256] [--cycles-spp 256]
         [--bounces 4] [--lighting sun,hdri] [--store tests/render/data/principled_cycles.json]
     .venv/bin/python tools/principled_vs_cycles.py --time-scene tabletop --res 160x120 --spp 64
         (time per sample of a color benchmark scene with each principled model, no Cycles)

The scene: 3 rows of 6 spheres (0.36 m across) over a grey Lambertian floor, each sphere one material of
:data:`SWEEP` (base colors x roughness x metallic x Specular IOR Level x coat x transmission), lit either by a
sun (3 W/m^2, 50 degrees above the horizon) under a uniform grey-blue sky (``sun``), or by the generated sky
HDRI of tools/color_quality.py with its small bright sun (``hdri``). Both engines render the same meshes and
vertex normals at fixed sample counts with equal bounces in every lobe (``--bounces`` Cycles bounces = Mitsuba
depth + 2), no clamping, no glossy filter, a one-pixel box filter, no denoising, no light tree: converged
estimates of the same integral. Cycles runs through ``bpy`` 4.2 in ``.venv-bpy`` (tools/cycles_render.py,
the color benchmark's worker; BlenderProc 2.8's Blender).

Printed for each object: its mean linear radiance over the pixels well inside its silhouette (masks from an
analytic ray cast of the spheres and the floor), and the ratio hybridgen / Cycles per channel for Mitsuba's
``principled`` (before, ``HYBRIDGEN_PRINCIPLED=mitsuba``) and hybridgen's Principled BSDF (after,
``HYBRIDGEN_PRINCIPLED=blender``), with each image's overall ratio. ``--store`` writes the scene settings and
Cycles' per-object means as the JSON table tests/render/test_principled_vs_cycles.py checks.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SWEEP: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # (name, base color, Material fields / Principled extras)
    ("red_s0", (0.8, 0.1, 0.1), dict(roughness=0.4, specular=0.0)),
    ("red_s05_r02", (0.8, 0.1, 0.1), dict(roughness=0.2, specular=0.5)),
    ("red_s05_r06", (0.8, 0.1, 0.1), dict(roughness=0.6, specular=0.5)),
    ("red_s1_r03", (0.8, 0.1, 0.1), dict(roughness=0.3, specular=1.0)),
    ("blue_s05_r04", (0.05, 0.1, 0.4), dict(roughness=0.4, specular=0.5)),
    ("white_s05_r05", (0.9, 0.9, 0.85), dict(roughness=0.5, specular=0.5)),
    ("grey_s05_r09", (0.5, 0.5, 0.5), dict(roughness=0.9, specular=0.5)),
    ("grey_s1_r01", (0.5, 0.5, 0.5), dict(roughness=0.1, specular=1.0)),
    ("dark_s05_r03", (0.03, 0.03, 0.03), dict(roughness=0.3, specular=0.5)),
    ("gold_m1_r03", (1.0, 0.77, 0.34), dict(roughness=0.3, metallic=1.0)),
    ("grey_m1_r06", (0.6, 0.6, 0.6), dict(roughness=0.6, metallic=1.0)),
    ("copper_m1_r1", (0.95, 0.64, 0.54), dict(roughness=1.0, metallic=1.0)),
    ("green_m05_r04", (0.2, 0.7, 0.3), dict(roughness=0.4, metallic=0.5)),
    ("red_coat", (0.8, 0.1, 0.1), dict(roughness=0.5, specular=0.5, extra=dict(coat_weight=1.0, coat_roughness=0.1))),
    ("blue_coat_tint", (0.1, 0.2, 0.6), dict(roughness=0.6, specular=0.5,
                                             extra=dict(coat_weight=0.7, coat_roughness=0.3, coat_tint=(1.0, 0.8, 0.5)))),
    ("glass_r02", (1.0, 1.0, 1.0), dict(roughness=0.2, transmission=1.0, ior=1.5)),
    ("green_glass_r05", (0.3, 0.9, 0.4), dict(roughness=0.5, transmission=1.0, ior=1.45)),
    ("aniso_metal", (0.9, 0.9, 0.9), dict(roughness=0.4, metallic=1.0, extra=dict(anisotropic=0.8))),
]
COLUMNS, SPACING, DIAMETER = 6, 0.46, 0.36
LIGHTINGS = ("sun", "hdri")


TEST_OBJECTS = ("red_s1_r03", "white_s05_r05", "grey_m1_r06", "copper_m1_r1")
"""The spheres of the small test view (``--store``; tests/render/test_principled_vs_cycles.py): objects whose
color Mitsuba's principled got 7-55 % wrong."""


def sweep(names: tuple[str, ...] | None = None) -> list[tuple[str, tuple[float, float, float], dict[str, Any]]]:
    """The :data:`SWEEP` entries named ``names`` (all by default), in that order."""
    if names is None:
        return list(SWEEP)
    entries = {entry[0]: entry for entry in SWEEP}
    return [entries[name] for name in names]


def sphere_centers(count: int) -> list[tuple[float, float, float]]:
    """World centres (m) of ``count`` spheres: rows of :data:`COLUMNS` along x, row 0 nearest the camera (-y)."""
    columns = min(COLUMNS, count)
    rows = math.ceil(count / columns)
    return [((i % columns - (columns - 1) / 2) * SPACING, (i // columns - (rows - 1) / 2) * SPACING, DIAMETER / 2)
            for i in range(count)]


def build_scene(lighting: str, width: int, height: int, workdir: Path,
                names: tuple[str, ...] | None = None) -> Any:
    """The sweep scene (or only the spheres ``names``, in one row, framed closer) under ``lighting``
    (:data:`LIGHTINGS`) at ``width`` x ``height`` px."""
    import hybridgen as hg

    scene = hg.Scene()
    floor = hg.make_primitive("plane", 6.0, name="floor", category_id=1, color=(0.5, 0.5, 0.5))
    floor.material.specular = 0.0
    scene.add(floor)
    entries = sweep(names)
    for index, ((name, color, values), center) in enumerate(zip(entries, sphere_centers(len(entries)))):
        ball = hg.make_primitive("sphere", DIAMETER, name=name, category_id=index + 2, color=color,
                                 local2world=hg.object_pose(list(center)))
        for key, value in values.items():
            if key == "extra":
                ball.material.extra = dict(value)
            else:
                setattr(ball.material, key, value)
        scene.add(ball)
    if lighting == "sun":
        scene.world.color, scene.world.strength = (0.3, 0.35, 0.45), 1.0
        scene.add_light(hg.Light("sun", "SUN", energy=3.0,
                                 local2world=hg.object_pose([0, 0, 5], [math.radians(40), 0, math.radians(30)])))
    else:
        sys.path.insert(0, str(REPO / "tools"))
        from color_quality import sky_hdri

        scene.world.hdri_path = str(sky_hdri(workdir / "sky.exr"))
        scene.world.strength, scene.world.hdri_rotation = 1.0, 0.3
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.75, width, height, clip_start=0.01)
    location = [0.0, -2.6, 1.9] if names is None else [0.0, -1.9, 1.1]
    scene.camera.add_keypoint(hg.look_at(location, [0.0, 0.05, 0.1]))
    return scene


def object_masks(scene: Any, names: tuple[str, ...] | None = None, margin: float = 0.8) -> dict[str, np.ndarray]:
    """Per object name, the pixels (bool H x W) whose centre ray first hits it, spheres only where the ray passes
    within ``margin`` x radius of the centre (away from silhouettes and from the tessellation's edge)."""
    intr = scene.camera.intrinsics
    pose = scene.camera.keypoints[0]
    v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], axis=-1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    origin = pose[:3, 3]
    distance = np.full(u.shape, np.inf)
    owner = np.full(u.shape, -1)
    inner = np.zeros(u.shape, bool)
    radius = DIAMETER / 2
    entries = sweep(names)
    for index, center in enumerate(sphere_centers(len(entries))):
        oc = origin - np.asarray(center)
        b = rays @ oc
        closest2 = oc @ oc - b * b
        t = -b - np.sqrt(np.maximum(radius * radius - closest2, 0.0))
        hit = (closest2 < radius * radius) & (t > 0) & (t < distance)
        distance[hit], owner[hit] = t[hit], index + 1
        inner[hit] = closest2[hit] < (margin * radius) ** 2
    t_floor = -origin[2] / np.minimum(rays[..., 2], -1e-9)
    floor = (rays[..., 2] < 0) & (t_floor < distance) & (np.abs(origin[0] + t_floor * rays[..., 0]) < 2.5)
    masks = {"floor": floor}
    for index, (name, _, _) in enumerate(entries):
        masks[name] = (owner == index + 1) & inner & ~floor
    return masks


def object_means(image: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, list[float]]:
    """Mean linear RGB of ``image`` over each mask."""
    return {name: image[mask].astype(np.float64).mean(axis=0).tolist() for name, mask in masks.items()}


def hybridgen_settings(bounces: int) -> Any:
    """hybridgen's settings for an estimate Cycles' reference mode matches: fixed samples, no clamp, no filter."""
    from hybridgen.render.pathtrace.path_trace_settings import PathTraceSettings

    return PathTraceSettings(noise_threshold=0.0, samples=1, max_bounces=bounces, glossy_bounces=bounces,
                             diffuse_bounces=bounces, transmission_bounces=bounces, clamp_indirect=0.0,
                             filter_width=0.0, filter_glossy=0.0, min_bounces=bounces)


def render_hybridgen(scene: Any, model: str, spp: int, bounces: int, seed: int = 0) -> tuple[np.ndarray, float]:
    """(linear RGB H x W x 3, seconds of rendering) with principled materials as ``model`` ("mitsuba" or
    "blender", :data:`hybridgen.render.pathtrace.principled_material.ENV_VARIABLE`)."""
    import time

    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.pathtrace.principled_material import ENV_VARIABLE

    os.environ[ENV_VARIABLE] = model
    extras = {obj.name: obj.material.extra for obj in scene.objects}
    if model == "mitsuba":  # Mitsuba's principled has no coat, tint or anisotropy: rendered without them
        for obj in scene.objects:
            obj.material.extra = {}
    try:
        view = PathTraceView(scene, hybridgen_settings(bounces), variant="llvm_ad_rgb")
    finally:
        for obj in scene.objects:
            obj.material.extra = extras[obj.name]
    view.render(scene.camera.keypoints[0], seed=seed + 1, spp=4)  # kernels compiled outside the timing
    start = time.perf_counter()
    image = view.render(scene.camera.keypoints[0], seed=seed, spp=spp)
    return np.asarray(image, np.float64), time.perf_counter() - start


def render_cycles(scene: Any, spp: int, bounces: int, workdir: Path) -> np.ndarray:
    """Cycles' linear RGB (H x W x 3) of the scene at ``spp`` with ``bounces`` in every lobe."""
    import mitsuba as mi

    sys.path.insert(0, str(REPO / "tools"))
    from cycles_export import export_for_cycles
    from cycles_worker import CyclesWorker, ensure_bpy_venv

    python = ensure_bpy_venv(REPO / ".venv-bpy")
    if python is None:
        raise SystemExit("no bpy venv (.venv-bpy): Cycles cannot run here")
    export_for_cycles(scene, workdir / "scene.npz", spp, bounces, bounces)
    worker = CyclesWorker(python, workdir / "scene.npz")
    try:
        exr = workdir / "cycles.exr"
        worker.render(0, False, 0, exr, cycles={"sample_clamp_indirect": 0.0, "sample_clamp_direct": 0.0,
                                               "blur_glossy": 0.0, "caustics_reflective": True,
                                               "caustics_refractive": True})
    finally:
        worker.close()
    mi.set_variant("llvm_ad_rgb")
    bitmap = mi.Bitmap(str(exr)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    return np.asarray(bitmap, np.float64)


TEST_RES, TEST_CYCLES_SPP = (64, 48), 4096


def test_view(bounces: int) -> dict[str, Any]:
    """Cycles' per-object means of the small test view (:data:`TEST_OBJECTS` under the sun, :data:`TEST_RES`)."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = build_scene("sun", *TEST_RES, Path(tmp), TEST_OBJECTS)
        masks = object_masks(scene, TEST_OBJECTS)
        cycles = object_means(render_cycles(scene, TEST_CYCLES_SPP, bounces, Path(tmp)), masks)
    return {"lighting": "sun", "res": list(TEST_RES), "cycles_spp": TEST_CYCLES_SPP, "bounces": bounces,
            "objects": list(TEST_OBJECTS), "pixels": {n: int(m.sum()) for n, m in masks.items()}, "cycles": cycles}


def ratio_row(name: str, cycles: list[float], ours: dict[str, list[float]]) -> str:
    cells = [f"{name:16s}", " ".join(f"{c:7.4f}" for c in cycles)]
    for model in ("mitsuba", "blender"):
        ratio = np.asarray(ours[model]) / np.maximum(cycles, 1e-9)
        cells.append(" ".join(f"{r:6.3f}" for r in ratio) + f" ({float(np.mean(ours[model]) / np.mean(cycles)):6.3f})")
    return " | ".join(cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--res", default="360x240")
    parser.add_argument("--spp", type=int, default=256, help="hybridgen's samples per pixel")
    parser.add_argument("--cycles-spp", type=int, default=256)
    parser.add_argument("--bounces", type=int, default=4)
    parser.add_argument("--lighting", default=",".join(LIGHTINGS))
    parser.add_argument("--store", type=Path, help="write Cycles' per-object means as a JSON table")
    parser.add_argument("--time-scene", help="only time a color benchmark scene (tabletop, materials, ...) per "
                        "sample with each model, at --res and --spp, alternating --repeats times")
    parser.add_argument("--repeats", type=int, default=8)
    args = parser.parse_args()
    width, height = (int(v) for v in args.res.split("x"))
    if args.time_scene:
        sys.path.insert(0, str(REPO / "tools"))
        from principled_timing import time_per_sample

        time_per_sample(args.time_scene, (width, height), args.spp, args.repeats)
        return
    table: dict[str, Any] = {"res": [width, height], "cycles_spp": args.cycles_spp, "bounces": args.bounces,
                             "blender": None, "lightings": {}}
    for lighting in args.lighting.split(","):
        with tempfile.TemporaryDirectory() as tmp:
            workdir = Path(tmp)
            scene = build_scene(lighting, width, height, workdir)
            masks = object_masks(scene)
            cycles = object_means(render_cycles(scene, args.cycles_spp, args.bounces, workdir), masks)
            ours, seconds = {}, {}
            for model in ("mitsuba", "blender"):
                image, seconds[model] = render_hybridgen(scene, model, args.spp, args.bounces)
                ours[model] = object_means(image, masks)
        print(f"\n{lighting}: {width}x{height}, hybridgen {args.spp} spp (mitsuba {seconds['mitsuba']:.1f} s, "
              f"blender {seconds['blender']:.1f} s), Cycles {args.cycles_spp} spp, {args.bounces} bounces")
        print(f"{'object':16s} | {'Cycles R G B':23s} | {'Mitsuba principled / Cycles (mean)':35s} | "
              f"hybridgen Principled / Cycles (mean)")
        for name in masks:
            print(ratio_row(name, cycles[name], {m: ours[m][name] for m in ours}))
        table["lightings"][lighting] = {"pixels": {n: int(m.sum()) for n, m in masks.items()}, "cycles": cycles,
                                        "hybridgen": ours["blender"]}
    if args.store:
        table["test_view"] = test_view(args.bounces)
        args.store.parent.mkdir(parents=True, exist_ok=True)
        args.store.write_text(json.dumps(table, indent=1) + "\n")
        print(f"stored {args.store}")


if __name__ == "__main__":
    main()
