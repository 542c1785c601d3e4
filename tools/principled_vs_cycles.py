"""hybridgen's color against Blender 4.2's Cycles, object by object, on sweeps of Principled materials.

Run: .venv/bin/python tools/principled_vs_cycles.py [--group principled|layers|subsurface] [--res 360x240]
         [--spp 256] [--cycles-spp 256] [--bounces 4] [--lighting sun,area,hdri] [--reuse-cycles]
         [--store tests/render/data/principled_cycles.json]
     .venv/bin/python tools/principled_vs_cycles.py --time-scene tabletop --res 160x120 --spp 64
         (time per sample of a color benchmark scene with each principled model, no Cycles)

The scenes (tools/principled_sweep.py): rows of spheres over a grey Lambertian floor, each sphere one material
of a sweep - ``principled``: base colors x roughness x metallic x Specular IOR Level x coat x transmission x
anisotropy; ``layers``: sheen and subsurface; ``subsurface``: subsurface weights x radius scales (no test view);
``coat_normal``: a normal map on Normal and / or Coat Normal of coated UV spheres; ``emission``: emissive spheres
under coat and sheen - under a sun and sky (``sun``), a square area light in a black world (``area``), a sky HDRI
(``hdri``) or nothing (``dark``, the emission group's). Scenes with normal maps, layered emission or an area light
render in Cycles through tools/cycles_render_layers.py. Both engines render the same meshes and vertex
normals at fixed sample counts with equal bounces in every lobe (``--bounces`` Cycles bounces = Mitsuba
depth + 2), no clamping, no glossy filter, a one-pixel box filter, no denoising, no light tree: converged
estimates of the same integral. Cycles runs through ``bpy`` 4.2 in ``.venv-bpy`` (tools/cycles_render.py,
the color benchmark's worker; BlenderProc 2.8's Blender).

Printed for each object: its mean linear radiance over the pixels well inside its silhouette (masks from an
analytic ray cast of the spheres and the floor), and the ratio hybridgen / Cycles per channel for "before"
and hybridgen's Principled BSDF ("after", ``HYBRIDGEN_PRINCIPLED=blender``), with each image's overall ratio.
"Before" is per group (:data:`BEFORE`): Mitsuba's ``principled`` (``HYBRIDGEN_PRINCIPLED=mitsuba``) for the
``principled`` sweep, hybridgen's BSDF with the sheen and subsurface inputs dropped for ``layers``, the coat bent by
the base's map for ``coat_normal``, emission unweighted by the layers for ``emission``; when Cycles is rendered, the
per-pixel relative RMS difference of each model's image to Cycles' is printed per object too.
``--test-view-only`` (with ``--store``) renders and stores only the group's test views (:data:`TEST_VIEWS`) under
the lightings asked for. ``--reuse-cycles`` takes Cycles' means from the ``--store`` table instead of rendering
(hybridgen changed, Cycles did not). ``--store`` writes the scene settings and Cycles' per-object means of the
group's sweep and test views into the JSON table tests/render/test_principled_vs_cycles.py checks (the other
groups' entries are kept, and the group's other lightings when res, spp and bounces are the same).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))
from principled_sweep import (GROUP_LIGHTINGS, GROUPS, LIGHTINGS, TEST_AREA_OBJECTS,  # noqa: E402,F401
                              TEST_COAT_NORMAL_OBJECTS, TEST_EMISSION_OBJECTS, TEST_GLASS_OBJECTS, TEST_LAYER_OBJECTS,
                              TEST_OBJECTS,
                              build_scene, object_masks, object_means)

LAYER_INPUTS = ("sheen_", "subsurface_")
"""Prefixes of the ``extra`` inputs the ``layers`` sweep's "before" drops."""
TEST_VIEWS = {"test_view": ("principled", "sun", TEST_OBJECTS),
              "test_view_area": ("principled", "area", TEST_AREA_OBJECTS),
              "test_view_glass": ("principled", "hdri", TEST_GLASS_OBJECTS),
              "test_view_layers": ("layers", "sun", TEST_LAYER_OBJECTS),
              "test_view_coat_normal": ("coat_normal", "sun", TEST_COAT_NORMAL_OBJECTS),
              "test_view_emission": ("emission", "dark", TEST_EMISSION_OBJECTS)}
"""The small test views, by their key in the stored table: (sweep group, lighting, spheres). ``--store`` renders
those of ``--group`` whose lighting it renders."""
IMAGE_VIEWS = ("test_view_area", "test_view_coat_normal", "test_view_emission")
"""Test views whose Cycles image is stored too (:data:`IMAGES`), for a pixel-by-pixel comparison."""
BEFORE = {"principled": "mitsuba", "layers": "before", "coat_normal": "flat_coat", "emission": "unlayered_emission",
          "subsurface": "before"}
"""Per group, the model its "before" column renders: Mitsuba's ``principled``; hybridgen's BSDF without the sheen
and subsurface inputs; the coat bent by the base's normal map (the ``normalmap`` wrapper around the whole BSDF,
the coat normal map ignored); emission not weighted by the coat and sheen above it."""


def hybridgen_settings(bounces: int) -> Any:
    """hybridgen's settings for an estimate Cycles' reference mode matches: fixed samples, no clamp, no filter."""
    from hybridgen.render.pathtrace.path_trace_settings import PathTraceSettings

    return PathTraceSettings(noise_threshold=0.0, samples=1, max_bounces=bounces, glossy_bounces=bounces,
                             diffuse_bounces=bounces, transmission_bounces=bounces, clamp_indirect=0.0,
                             filter_width=0.0, filter_glossy=0.0, min_bounces=bounces)


def render_hybridgen(scene: Any, model: str, spp: int, bounces: int, seed: int = 0) -> tuple[np.ndarray, float]:
    """(linear RGB H x W x 3, seconds of rendering) with principled materials as ``model`` ("mitsuba" or
    "blender", :data:`hybridgen.render.pathtrace.principled_material.ENV_VARIABLE`; "before": "blender" without
    the :data:`LAYER_INPUTS`; "flat_coat" / "unlayered_emission": see :data:`BEFORE`)."""
    import time

    from hybridgen.render.pathtrace import principled_material
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.pathtrace.principled_material import ENV_VARIABLE

    os.environ[ENV_VARIABLE] = "mitsuba" if model == "mitsuba" else "blender"
    layer_normals = principled_material.layer_normals
    if model == "flat_coat":
        principled_material.layer_normals = lambda material: False
    extras = {obj.name: obj.material.extra for obj in scene.objects}
    for obj in scene.objects:  # Mitsuba's principled has no coat, tint, anisotropy, sheen or subsurface
        if model == "mitsuba":
            obj.material.extra = {}
        elif model == "before":
            obj.material.extra = {k: v for k, v in obj.material.extra.items() if not k.startswith(LAYER_INPUTS)}
    try:
        view = PathTraceView(scene, hybridgen_settings(bounces), variant="llvm_ad_rgb")
    finally:
        principled_material.layer_normals = layer_normals
        for obj in scene.objects:
            obj.material.extra = extras[obj.name]
    if model == "unlayered_emission":
        view.mi_scene.integrator().layered_emitters = []
    view.render(scene.camera.keypoints[0], seed=seed + 1, spp=4)  # kernels compiled outside the timing
    start = time.perf_counter()
    image = view.render(scene.camera.keypoints[0], seed=seed, spp=spp)
    return np.asarray(image, np.float64), time.perf_counter() - start


def render_cycles(scene: Any, spp: int, bounces: int, workdir: Path) -> np.ndarray:
    """Cycles' linear RGB (H x W x 3) of the scene at ``spp`` with ``bounces`` in every lobe."""
    import mitsuba as mi

    sys.path.insert(0, str(REPO / "tools"))
    from cycles_export import export_for_cycles
    from cycles_render_layers import export_layers, needs_layers
    from cycles_render_layers import worker as layers_worker
    from cycles_worker import CyclesWorker, ensure_bpy_venv

    python = ensure_bpy_venv(REPO / ".venv-bpy")
    if python is None:
        raise SystemExit("no bpy venv (.venv-bpy): Cycles cannot run here")
    export_for_cycles(scene, workdir / "scene.npz", spp, bounces, bounces)
    if needs_layers(scene):  # normal maps, emission under coat / sheen: tools/cycles_render_layers.py
        export_layers(scene, workdir / "scene.npz")
        worker = layers_worker(python, workdir / "scene.npz")
    else:
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
TEST_VIEW_RES = {"coat_normal": (128, 64), "test_view_glass": (128, 96)}
"""Test views larger than :data:`TEST_RES`, by view key or group (the coat normal map's pattern is compared pixel by
pixel; the glass spheres' means need their pixels: at 64 x 48 seeds left them up to 3 % off at 256 spp)."""
IMAGES = "principled_cycles_images.npz"
"""Beside the ``--store`` table: Cycles' images (float32 H x W x 3) of the :data:`IMAGE_VIEWS`, under the views'
keys."""


def test_view(bounces: int, objects: tuple[str, ...] = TEST_OBJECTS, lighting: str = "sun",
              res: tuple[int, int] = TEST_RES) -> tuple[dict[str, Any], np.ndarray]:
    """Cycles' per-object means of a small test view (``objects`` under ``lighting`` at ``res``) and its image."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = build_scene(lighting, *res, Path(tmp), objects)
        masks = object_masks(scene, objects)
        image = render_cycles(scene, TEST_CYCLES_SPP, bounces, Path(tmp))
        cycles = object_means(image, masks)
    return {"lighting": lighting, "res": list(res), "cycles_spp": TEST_CYCLES_SPP, "bounces": bounces,
            "objects": list(objects), "pixels": {n: int(m.sum()) for n, m in masks.items()},
            "cycles": cycles}, image.astype(np.float32)


def pixel_errors(image: np.ndarray, reference: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, float]:
    """Per object: the RMS over its pixels of (image - reference) in the mean of R, G, B, over the reference's mean
    there (both engines' noise included: compare models rendered alike)."""
    a, b = image.mean(axis=-1), reference.mean(axis=-1)
    return {name: float(np.sqrt(np.mean((a[m] - b[m]) ** 2)) / max(float(b[m].mean()), 1e-12))
            for name, m in masks.items()}


def ratio_row(name: str, cycles: list[float], ours: dict[str, list[float]]) -> str:
    cells = [f"{name:17s}", " ".join(f"{c:7.4f}" for c in cycles)]
    for model in ours:
        ratio = np.asarray(ours[model]) / np.maximum(cycles, 1e-9)
        cells.append(" ".join(f"{r:6.3f}" for r in ratio) + f" ({float(np.mean(ours[model]) / np.mean(cycles)):6.3f})")
    return " | ".join(cells)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--group", default="principled", choices=sorted(GROUPS))
    parser.add_argument("--res", default="360x240")
    parser.add_argument("--spp", type=int, default=256, help="hybridgen's samples per pixel")
    parser.add_argument("--cycles-spp", type=int, default=256)
    parser.add_argument("--bounces", type=int, default=4)
    parser.add_argument("--lighting", help="default: sun,area,hdri (the emission group: dark)")
    parser.add_argument("--store", type=Path, help="write Cycles' per-object means into this JSON table")
    parser.add_argument("--reuse-cycles", action="store_true", help="Cycles' means from the --store table")
    parser.add_argument("--time-scene", help="only time a color benchmark scene (tabletop, materials, ...) per "
                        "sample with each model, at --res and --spp, alternating --repeats times")
    parser.add_argument("--repeats", type=int, default=8)
    parser.add_argument("--test-view-only", action="store_true", help="with --store: render and store only the "
                        "group's test view (the sweep's stored values kept)")
    args = parser.parse_args()
    width, height = (int(v) for v in args.res.split("x"))
    if args.time_scene:
        from principled_timing import time_per_sample

        time_per_sample(args.time_scene, (width, height), args.spp, args.repeats)
        return
    stored = json.loads(args.store.read_text()) if args.store and args.store.exists() else {}
    part = stored if args.group == "principled" else stored.setdefault(args.group, {})
    lightings = args.lighting.split(",") if args.lighting else GROUP_LIGHTINGS.get(args.group, LIGHTINGS)
    if not args.reuse_cycles and not args.test_view_only:
        settings = {"res": [width, height], "cycles_spp": args.cycles_spp, "bounces": args.bounces}
        same = all(part.get(key) == value for key, value in settings.items())  # other lightings still valid
        kept = {k: v for k, v in part.get("lightings", {}).items() if same and k not in lightings}
        part.update({**settings, "blender": None, "lightings": kept})
    models = (BEFORE[args.group], "blender")
    for lighting in () if args.test_view_only else lightings:
        with tempfile.TemporaryDirectory() as tmp:
            workdir = Path(tmp)
            scene = build_scene(lighting, width, height, workdir, group=args.group)
            masks = object_masks(scene, group=args.group)
            reference = None if args.reuse_cycles else render_cycles(scene, args.cycles_spp, args.bounces, workdir)
            cycles = part["lightings"][lighting]["cycles"] if reference is None else object_means(reference, masks)
            ours, seconds, errors = {}, {}, {}
            for model in models:
                image, seconds[model] = render_hybridgen(scene, model, args.spp, args.bounces)
                ours[model] = object_means(image, masks)
                if reference is not None:
                    errors[model] = pixel_errors(image, reference, masks)
        print(f"\n{lighting}: {width}x{height}, hybridgen {args.spp} spp ("
              + ", ".join(f"{m} {seconds[m]:.1f} s" for m in models) + f"), Cycles {args.cycles_spp} spp, "
              f"{args.bounces} bounces")
        print(f"{'object':17s} | {'Cycles R G B':23s} | " + " | ".join(f"{m} / Cycles (mean)" for m in models))
        for name in masks:
            print(ratio_row(name, cycles[name], {m: ours[m][name] for m in ours}))
        if errors:  # the images' per-pixel agreement (sees a highlight or a pattern moved, which a mean may not)
            print("per-pixel relative RMS difference to Cycles: " + "; ".join(
                f"{name} " + " / ".join(f"{errors[m][name]:.3f}" for m in models) for name in masks))
        if not args.reuse_cycles:
            part["lightings"][lighting] = {"pixels": {n: int(m.sum()) for n, m in masks.items()},
                                           "cycles": cycles, "hybridgen": ours["blender"]}
    if args.store and not args.reuse_cycles:
        for key, (group, lighting, objects) in TEST_VIEWS.items():
            if group != args.group or lighting not in lightings:
                continue
            res = TEST_VIEW_RES.get(key, TEST_VIEW_RES.get(args.group, TEST_RES))
            stored[key], image = test_view(args.bounces, objects, lighting, res)
            if key in IMAGE_VIEWS:
                images_file = args.store.with_name(IMAGES)
                images = dict(np.load(images_file)) if images_file.exists() else {}
                np.savez_compressed(images_file, **{**images, key: image})
        args.store.parent.mkdir(parents=True, exist_ok=True)
        args.store.write_text(json.dumps(stored, indent=1) + "\n")
        print(f"stored {args.store}")


if __name__ == "__main__":
    main()
