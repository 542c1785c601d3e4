"""A/B of the denoiser's guides on the scenes of tools/color_quality.py: the same noisy hybridgen render (its
default settings) denoised once with the raster guides and once with guides that follow sharp specular
surfaces (hybridgen/render/pathtrace/specular_guides.py), each scored (8-bit sRGB) against the scene's fixed-spp
references without denoising, also per object (instance mask of the raster view). Same samples, so the
difference is the guides' alone.

Two independent references are rendered: the error is measured against their mean, and the references' own
noise (their squared difference / 4, which is what it adds to that error) is subtracted, so that a region where
the references are still noisy (glass at 2048 spp) does not hide the difference. Both numbers are printed.
``--checker-floor`` gives the floor a checker texture (detail seen through glass and in mirrors).

Run: .venv/bin/python tools/bench_denoise_guides.py [--res 160x120] [--reference-spp 2048] [--seeds 3]
     [--scenes materials,tabletop] [--checker-floor]
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import color_quality as cq
import numpy as np
from harness import Stopwatch


def main() -> None:
    from hybridgen.render.pathtrace.denoise import denoise
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.raster.raster_view import RasterView
    from hybridgen.render.tonemap import to_srgb8

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="160x120")
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scenes", default=",".join(cq.SCENES))
    parser.add_argument("--checker-floor", action="store_true")
    args = parser.parse_args()
    width, height = (int(x) for x in args.res.split("x"))
    print(f"load average at start: {open('/proc/loadavg').read().split()[:3]}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes.split(","):
            scene = cq.build(name, width, height, Path(tmp))
            if args.checker_floor:
                floor = next(obj for obj in scene.objects if obj.name == "floor")
                floor.material.base_color_texture = cq.checker(256, 16)
                cq.planar_uvs(floor, 1.0)
            cam = scene.camera.keypoints[0]
            view = PathTraceView(scene, PathTraceSettings())
            references = [to_srgb8(view.render(cam, seed=s, spp=args.reference_spp)).astype(np.float64)
                          for s in (987654, 456789)]
            reference = (references[0] + references[1]) / 2
            reference_noise = ((references[0] - references[1]) ** 2).sum(axis=2) / 4  # its share of the error
            ids = RasterView(scene).render(cam, ["instance_segmaps"])["instance_segmaps"]
            guides = DenoiseGuides(scene, filter_width=view.filter_width, follow_specular=True)
            rows = {"raster": [], "traced": []}
            per_object: dict[str, dict[str, list[float]]] = {"raster": {}, "traced": {}}
            seconds = {"raster": 0.0, "traced": 0.0}
            each: dict[str, list[list[float]]] = {"raster": [], "traced": []}  # MSE against each reference
            for seed in range(args.seeds):
                linear = view.render(cam, seed=seed + 1)
                for kind, through in (("raster", None), ("traced", view)):
                    watch = Stopwatch()
                    albedo, normals = guides.render(cam, through)
                    seconds[kind] += watch.read()[1]
                    image = to_srgb8(denoise(linear, albedo, normals)).astype(np.float64)
                    each[kind].append([float(((image - r) ** 2).mean()) for r in references])
                    squared = ((image - reference) ** 2).sum(axis=2)
                    rows[kind].append((squared.mean() / 3, (squared - reference_noise).mean() / 3))
                    squared = squared - reference_noise
                    for obj in scene.objects:
                        mask = ids == obj.instance_id
                        if mask.any():
                            per_object[kind].setdefault(obj.name, []).append(float(squared[mask].sum()))
            traced = guides.traced_subpixels
            guides.release()
            db = {k: [[10 * np.log10(255.0 ** 2 / max(m, 1e-9)) for m in pair] for pair in v] for k, v in rows.items()}
            print(f"{name}: PSNR raster guides {np.mean([d[0] for d in db['raster']]):.2f} dB, traced guides "
                  f"{np.mean([d[0] for d in db['traced']]):.2f} dB; without the references' noise "
                  f"{np.mean([d[1] for d in db['raster']]):.2f} -> {np.mean([d[1] for d in db['traced']]):.2f} dB "
                  f"(per seed: {[round(t[1] - r[1], 2) for t, r in zip(db['traced'], db['raster'])]} dB); "
                  f"guide CPU s/frame "
                  f"{seconds['raster'] / args.seeds:.3f} -> {seconds['traced'] / args.seeds:.3f}; "
                  f"{traced} sub-pixels traced")
            for index in range(2):  # the guides' difference scored against either reference alone
                gains = [10 * np.log10(r[index] / t[index]) for r, t in zip(each["raster"], each["traced"])]
                print(f"  against reference {index + 1} alone: {np.mean(gains):+.2f} dB "
                      f"(per seed {[round(g, 2) for g in gains]})")
            total = {k: sum(float(np.mean(v)) for v in per_object[k].values()) for k in per_object}
            for obj_name in per_object["raster"]:
                a, b = (float(np.mean(per_object[k][obj_name])) for k in ("raster", "traced"))
                if max(a, b) > 0.01 * total["raster"]:
                    print(f"  {obj_name}: share of squared error without the references' noise "
                          f"{a / total['raster']:.1%} -> {b / total['raster']:.1%} (of the raster-guided total)")
    print(f"load average at end: {open('/proc/loadavg').read().split()[:3]}")


if __name__ == "__main__":
    main()
