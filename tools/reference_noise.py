"""How much of bench_color's quality score is the reference's own noise: hybridgen's default color of the scenes of
tools/color_quality.py against two independent references of the same estimator.

Run: .venv/bin/python tools/reference_noise.py [--res 320x240] [--reference-spp 4096] [--scenes a,b]

``bench_color.py --quality`` scores each engine against ONE reference of its own estimator at a fixed spp; that
reference is noisy too, and its noise adds to the measured squared error whatever the image under test does:
``MSE(image, ref) = MSE(image, truth) + MSE(ref, truth)`` for independent errors. This tool renders (or finds in
the reference cache of tools/reference_cache.py) the benchmark's hybridgen reference (seed 12345) and a second
one at another seed (tools/color_references.py), and hybridgen's default color in this process
(``PathTraceSettings()`` + denoising, as tools/default_color_process.py, seed 1: tools/default_color.py). Per
scene it prints (8-bit sRGB, as the benchmark):

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
import tempfile
from pathlib import Path

import numpy as np
from color_quality import SCENES
from color_references import REFERENCE_SEED, SECOND_SEED, References, scene_and_content
from default_color import default_render
from image_scores import db, mse
from reference_cache import ReferenceCache, cache_root


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--scenes", default="")
    parser.add_argument("--reference-cache", default=None, help="folder of the reference cache (or 'off')")
    args = parser.parse_args()
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings

    width, height = (int(v) for v in args.res.lower().split("x"))
    resolution = f"{width}x{height}"
    workdir = Path(tempfile.mkdtemp(prefix="reference_noise_"))
    refs = References(ReferenceCache(cache_root(args.reference_cache)), args.reference_spp, resolution, "default",
                      None, workdir)
    print(f"{resolution}, references {args.reference_spp} spp (seeds {REFERENCE_SEED}, {SECOND_SEED})\n")
    print("| scene | ref floor MSE (ceiling dB) | default dB vs ref1 / ref2 / mean | own MSE | own share |")
    print("|---|---|---|---|---|")
    for name in args.scenes.split(",") if args.scenes else SCENES:
        scene, _, content = scene_and_content(name, width, height, workdir)
        ref1, ref2 = refs.hybridgen_pair(name, scene, content)
        image = default_render(scene, PathTraceSettings())["denoised"]
        floor = mse(ref1, ref2) / 2
        measured = mse(image, ref1)
        mean_ref = (ref1.astype(np.float64) + ref2) / 2
        print(f"| {name} | {floor:.3f} ({db(floor):.1f}) | {db(measured):.2f} / {db(mse(image, ref2)):.2f} / "
              f"{db(mse(image, mean_ref)):.2f} | {measured - floor:.3f} | {(measured - floor) / measured:.0%} |",
              flush=True)


if __name__ == "__main__":
    main()
