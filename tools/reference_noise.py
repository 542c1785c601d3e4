"""How much of bench_color's quality score is the reference's own noise: hybridgen's default color of the scenes of
tools/color_quality.py against two independent references of the same estimator.

Run: .venv/bin/python tools/reference_noise.py [--res 320x240] [--reference-spp 4096] [--scenes a,b]

``bench_color.py --quality`` scores each engine against ONE reference of its own estimator at a fixed spp; that
reference is noisy too, and its noise adds to the measured squared error whatever the image under test does:
``MSE(image, ref) = MSE(image, truth) + MSE(ref, truth)`` for independent errors. This tool renders (or finds in
the reference cache of tools/reference_cache.py) the benchmark's hybridgen reference (seed 12345) and a second
one at another seed, and hybridgen's default color in this process (``PathTraceSettings()`` + denoising, as
tools/default_color_process.py, seed 1). Per scene it prints (8-bit sRGB, as the benchmark):

- ``ref floor``: each reference's own squared error, ``MSE(ref1, ref2) / 2``, and the PSNR a perfect image
  would score against it (the benchmark's ceiling for that engine's estimator);
- the default image's PSNR against the benchmark's reference, against the second one and against their mean;
- ``own``: the default image's squared error with the reference's share taken out, ``MSE(image, ref1) -
  floor``, and its share of the measured error.

An estimator with less variance per sample lowers both its images' error and its reference's floor; a better
denoiser or sample allocation lowers only ``own``.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))

SECOND_SEED = 54321
"""Seed of the second reference (the benchmark's is color_quality.REFERENCE_SEED)."""


def mse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))


def db(value: float) -> float:
    """PSNR (dB) of an 8-bit mean squared error."""
    return float("inf") if value <= 0 else 10 * math.log10(255.0 ** 2 / value)


def default_color(scene: Any) -> np.ndarray:
    """hybridgen's default color of keypoint 0 (adaptive sampling, denoised), sRGB uint8, as
    tools/default_color_process.py renders it (seed 1)."""
    from hybridgen.render.pathtrace.denoise import denoise
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.render_color import keypoint_seed
    from hybridgen.render.tonemap import to_srgb8

    view = PathTraceView(scene, PathTraceSettings())
    guides = DenoiseGuides(scene, filter_width=view.filter_width)
    try:
        pose = scene.camera.keypoints[0]
        linear, _ = view.render_with_counts(pose, keypoint_seed(1, 0))
        return to_srgb8(denoise(linear, *guides.render(pose, view)))
    finally:
        guides.release()


def second_reference(refs: Any, name: str, scene: Any, content: str) -> np.ndarray:
    """hybridgen's reference at :data:`SECOND_SEED` (cached like the benchmark's)."""
    from color_quality import CLAMP
    from default_color_process import LOBES

    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.tonemap import to_srgb8

    key = {**refs._key(name, content), "seed": SECOND_SEED, "clamp_indirect": CLAMP, "lobes": refs.lobes,
           **refs.hybridgen_code}

    def render() -> tuple[np.ndarray, dict[str, Any]]:
        start = time.perf_counter()
        view = PathTraceView(scene, PathTraceSettings(samples=refs.spp, clamp_indirect=CLAMP, **LOBES[refs.lobes]))
        image = to_srgb8(view.render(scene.camera.keypoints[0], seed=SECOND_SEED))
        return image, {"seconds": time.perf_counter() - start}

    return refs.cache.fetch("hybridgen", key, render)[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--scenes", default="")
    parser.add_argument("--reference-cache", default=None, help="folder of the reference cache (or 'off')")
    args = parser.parse_args()

    import color_quality as cq
    from bench_color import export_for_cycles
    from reference_cache import ReferenceCache, cache_root, scene_digest

    width, height = (int(v) for v in args.res.lower().split("x"))
    resolution = f"{width}x{height}"
    workdir = Path(tempfile.mkdtemp(prefix="reference_noise_"))
    refs = cq.References(ReferenceCache(cache_root(args.reference_cache)), args.reference_spp, resolution, "default",
                         None, workdir)
    print(f"{resolution}, references {args.reference_spp} spp (seeds {cq.REFERENCE_SEED}, {SECOND_SEED})\n")
    print("| scene | ref floor MSE (ceiling dB) | default dB vs ref1 / ref2 / mean | own MSE | own share |")
    print("|---|---|---|---|---|")
    for name in args.scenes.split(",") if args.scenes else cq.SCENES:
        scene = cq.build(name, width, height, workdir)
        npz = workdir / f"{name}.npz"
        export_for_cycles(scene, npz, 1024, 3, 0)
        content = scene_digest(npz)
        ref1, _ = refs.hybridgen(name, scene, content, cq.CLAMP)
        ref2 = second_reference(refs, name, scene, content)
        image = default_color(scene)
        floor = mse(ref1, ref2) / 2
        measured = mse(image, ref1)
        mean_ref = (ref1.astype(np.float64) + ref2) / 2
        print(f"| {name} | {floor:.3f} ({db(floor):.1f}) | {db(measured):.2f} / {db(mse(image, ref2)):.2f} / "
              f"{db(mse(image, mean_ref)):.2f} | {measured - floor:.3f} | {(measured - floor) / measured:.0%} |",
              flush=True)


if __name__ == "__main__":
    main()
