"""Where hybridgen's default color spends its CPU and where its error is, object by object, for the scenes of
tools/color_quality.py (what limits ``bench_color.py --quality``'s score per CPU second).

Run: .venv/bin/python tools/color_regions.py [--scenes materials] [--res 320x240] [--reference-spp 4096]
         [--lobes default|blenderproc] [--threshold 0.005] [--paths 256]

Per scene, in this process (scene built once, 8-bit sRGB as the benchmark, seed 1 as its measured render):

- the default render (``PathTraceSettings()`` + denoising; ``--threshold`` overrides the noise threshold,
  ``--lobes blenderproc`` sets BlenderProc's glossy/transmission bounces 0) is scored against the benchmark's
  4096-spp reference and a second one at another seed (tools/reference_noise.py); its squared error is split
  by the object each pixel sees (the raster instance map; ``(background)`` for none) into ``ref`` (the
  references' own noise there, ``(ref1 - ref2)^2 / 2``) and ``own`` (the rest), before and after denoising,
  as shares of the image's mean squared error;
- each object's mean samples per pixel in that render, its pixels traced once more at a fixed 64 spp to get
  its CPU cost per sample, and from both its share of the render's sampling CPU;
- with ``--paths N``: the per-pixel variance of each object's raw sRGB values (two seeds at N spp, not rounded)
  with light path classes removed - all paths, direct light only (``max_bounces: 0``), no glossy bounce
  (``glossy_bounces: 0``), no transmission bounce (``transmission_bounces: 0``) - which says what kind of light
  carries the noise.

Numbers are CPU seconds of this process (user + system, both Dr.Jit threads); the machine may be shared.
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from color_lobes import LOBES
from color_references import References, scene_and_content
from default_color import default_render
from harness import Table, cpu_seconds
from image_scores import db, mse
from reference_cache import ReferenceCache, cache_root

PATH_CLASSES = {"all paths": {}, "direct only": {"max_bounces": 0}, "no glossy bounce": {"glossy_bounces": 0},
                "no transmission bounce": {"transmission_bounces": 0}}
"""``--paths``: settings that remove one class of light paths each (PathTraceSettings keywords)."""


def object_map(scene: Any) -> tuple[np.ndarray, dict[int, str]]:
    """The instance id each pixel centre sees (H x W; 0 = none) and the objects' names by id."""
    from hybridgen.render.raster.scene_raster import SceneRaster

    raster = SceneRaster(scene)
    try:
        ids = np.asarray(raster.view.render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"])
    finally:
        raster.release()
    return ids, {0: "(background)", **{obj.instance_id: obj.name for obj in scene.objects}}


def srgb_float(linear: np.ndarray) -> np.ndarray:
    """The sRGB values of :func:`hybridgen.render.tonemap.to_srgb8` (0..255, float64), not rounded."""
    from hybridgen.render.tonemap import srgb_encode

    return srgb_encode(linear).astype(np.float64) * 255.0


def sample_cost(view: Any, pixels: np.ndarray, spp: int = 64) -> float:
    """CPU seconds per sample of tracing ``pixels`` (flat indices) at a fixed ``spp``."""
    start = cpu_seconds()
    view._tracer.trace(pixels, spp, 7)
    return (cpu_seconds() - start) / max(len(pixels) * spp, 1)


def path_variances(scene: Any, base: dict[str, Any], ids: np.ndarray, spp: int) -> dict[str, dict[int, float]]:
    """Per light path class (:data:`PATH_CLASSES`): each object's mean per-pixel variance of raw sRGB values."""
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

    out = {}
    for name, change in PATH_CLASSES.items():
        view = PathTraceView(scene, PathTraceSettings(**{**base, **change}))
        frames = [srgb_float(view.render(scene.camera.keypoints[0], seed=seed, spp=spp)) for seed in (11, 22)]
        variance = ((frames[0] - frames[1]) ** 2).mean(axis=2) / 2
        out[name] = {int(i): float(variance[ids == i].mean()) for i in np.unique(ids)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="materials", help="comma-separated scene names of color_quality.py")
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--lobes", choices=sorted(LOBES), default="default")
    parser.add_argument("--threshold", type=float, default=None, help="noise threshold (default: hybridgen's)")
    parser.add_argument("--paths", type=int, default=0, help="spp of the light-path variance table (0: skip)")
    parser.add_argument("--reference-cache", default=None, help="folder of the reference cache (or 'off')")
    args = parser.parse_args()

    from hybridgen.render.pathtrace.path_trace import PathTraceSettings

    width, height = (int(v) for v in args.res.lower().split("x"))
    resolution = f"{width}x{height}"
    workdir = Path(tempfile.mkdtemp(prefix="color_regions_"))
    refs = References(ReferenceCache(cache_root(args.reference_cache)), args.reference_spp, resolution, args.lobes,
                      None, workdir)
    base = {"noise_threshold": args.threshold, **LOBES[args.lobes]}
    for name in args.scenes.split(","):
        scene, _, content = scene_and_content(name, width, height, workdir)
        ref1, ref2 = refs.hybridgen_pair(name, scene, content)
        ids, names = object_map(scene)
        run = default_render(scene, PathTraceSettings(**base))
        counts = run["counts"].ravel()
        ref_noise = ((ref1.astype(np.float64) - ref2) ** 2).mean(axis=2) / 2
        total = mse(run["denoised"], ref1)
        print(f"\n{name} {resolution}, lobes {args.lobes}, threshold {args.threshold or 'default'}: "
              f"{db(total):.2f} dB against the reference ({db(mse(run['denoised'], ref2)):.2f} against the "
              f"second), image MSE {total:.3f} of which the references' own noise {ref_noise.mean():.3f}; mean spp "
              f"{counts.mean():.0f}, sampling CPU {run['trace_cpu']:.2f} s, guides + denoising "
              f"{run['denoise_cpu']:.2f} s")
        table = Table([("object", ""), ("pixels", ".1%"), ("mean spp", ".0f"), ("CPU ns/sample", ".0f"),
                       ("sampling CPU share", ".0%"), ("own share (raw)", ""), ("ref share", ".0%")], markdown=True)
        table.header()
        errors = {key: ((run[key].astype(np.float64) - ref1) ** 2).mean(axis=2) for key in ("denoised", "raw")}
        cost = {int(i): sample_cost(run["view"], np.flatnonzero(ids.ravel() == i)) for i in np.unique(ids)}
        spent = {i: cost[i] * counts[ids.ravel() == i].sum() for i in cost}
        for i in np.unique(ids):
            mask = ids == i
            own = {key: float((e - ref_noise)[mask].sum() / e.size) / total for key, e in errors.items()}
            table.row(str(names.get(int(i), i)), mask.mean(), counts[mask.ravel()].mean(), cost[int(i)] * 1e9,
                      spent[int(i)] / sum(spent.values()), f"{own['denoised']:.0%} ({own['raw']:.0%})",
                      ref_noise[mask].sum() / ref_noise.size / total)
        if args.paths:
            table = path_variances(scene, base, ids, args.paths)
            print(f"\nper-pixel variance of raw sRGB values (0..255, two seeds at {args.paths} spp):")
            print("| object | " + " | ".join(table) + " |")
            print("|---|" + "---|" * len(table))
            for i in np.unique(ids):
                print(f"| {names.get(int(i), i)} | " + " | ".join(f"{v[int(i)]:.2f}" for v in table.values()) + " |")


if __name__ == "__main__":
    main()
