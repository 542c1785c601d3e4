"""A/B of the denoiser's guides on the scenes of tools/color_quality.py: the same noisy hybridgen render (its
default settings) denoised once with the raster guides and once with guides that follow sharp specular
surfaces (hybridgen/render/specular_guides.py), each scored (8-bit sRGB PSNR) against the scene's fixed-spp
reference without denoising, also per object (instance mask of the raster view). Same samples, so the
difference is the guides' alone.

Run: .venv/bin/python tools/bench_denoise_guides.py [--res 160x120] [--reference-spp 2048] [--seeds 3]
     [--scenes materials,tabletop]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> None:
    import color_quality as cq

    from hybridgen.render.denoise import denoise
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.raster import RasterView
    from hybridgen.render.tonemap import to_srgb8

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="160x120")
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scenes", default=",".join(cq.SCENES))
    args = parser.parse_args()
    width, height = (int(x) for x in args.res.split("x"))
    print(f"load average at start: {open('/proc/loadavg').read().split()[:3]}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes.split(","):
            scene = cq.build(name, width, height, Path(tmp))
            cam = scene.camera.keypoints[0]
            view = PathTraceView(scene, PathTraceSettings())
            reference = to_srgb8(view.render(cam, seed=987654, spp=args.reference_spp))
            ids = RasterView(scene).render(cam, ["instance_segmaps"])["instance_segmaps"]
            guides = DenoiseGuides(scene, filter_width=view.filter_width)
            rows = {"raster": [], "traced": []}
            per_object: dict[str, dict[str, list[float]]] = {"raster": {}, "traced": {}}
            seconds = {"raster": 0.0, "traced": 0.0}
            for seed in range(args.seeds):
                linear = view.render(cam, seed=seed + 1)
                for kind, through in (("raster", None), ("traced", view)):
                    start = time.process_time()
                    albedo, normals = guides.render(cam, through)
                    seconds[kind] += time.process_time() - start
                    image = to_srgb8(denoise(linear, albedo, normals))
                    rows[kind].append(cq.psnr(image, reference))
                    squared = ((image.astype(np.float64) - reference) ** 2).sum(axis=2)
                    for obj in scene.objects:
                        mask = ids == obj.instance_id
                        if mask.any():
                            per_object[kind].setdefault(obj.name, []).append(float(squared[mask].sum()))
            traced = guides.traced_subpixels
            guides.release()
            print(f"{name}: PSNR raster guides {np.mean(rows['raster']):.2f} dB, traced guides "
                  f"{np.mean(rows['traced']):.2f} dB ({args.seeds} seeds: "
                  f"{[round(a - b, 2) for a, b in zip(rows['traced'], rows['raster'])]} dB); guide CPU s/frame "
                  f"{seconds['raster'] / args.seeds:.3f} -> {seconds['traced'] / args.seeds:.3f}; "
                  f"{traced} sub-pixels traced")
            total = {k: sum(float(np.mean(v)) for v in per_object[k].values()) for k in per_object}
            for obj_name in per_object["raster"]:
                a, b = (float(np.mean(per_object[k][obj_name])) for k in ("raster", "traced"))
                if max(a, b) > 0.01 * total["raster"]:
                    print(f"  {obj_name}: share of squared error {a / total['raster']:.1%} -> "
                          f"{b / total['raster']:.1%} (of the raster-guided total)")
    print(f"load average at end: {open('/proc/loadavg').read().split()[:3]}")


if __name__ == "__main__":
    main()
