"""Where the color noise goes: hybridgen's raw (undenoised) estimator vs Blender Cycles' at EQUAL spp, per scene
of tools/color_quality.py, each against its own high-spp reference.

Run: .venv/bin/python tools/color_decompose.py [--res 160x120] [--spp 64] [--reference-spp 2048]
     [--scenes a,b] [--variants default,bp] [--no-cycles]

Variants of hybridgen's fixed-spp estimator (``samples: N``, no denoising), each with its own reference:
``default`` (hybridgen's defaults), ``bp`` (glossy/transmission bounces 0, the paths Cycles renders at
BlenderProc's defaults), ``direct`` (max_bounces 0), ``noclamp`` (clamp_indirect 0); Cycles in
``mode: reference`` (BlenderProc's estimator at a fixed spp, tools/cycles_render.py), saved as linear EXR.
Printed per scene and variant: PSNR (8-bit sRGB) and relative MSE of the linear image (mean over pixels of
``|x - ref|^2 / (ref^2 + 1e-2)``), so estimators are compared at equal spp.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
from color_quality import SCENES, build
from cycles_export import export_for_cycles
from cycles_worker import CyclesWorker, ensure_bpy_venv
from harness import Stopwatch
from image_scores import psnr

REPO = Path(__file__).resolve().parents[1]

VARIANTS: dict[str, dict[str, Any]] = {
    "default": {},
    "bp": {"glossy_bounces": 0, "transmission_bounces": 0},
    "direct": {"max_bounces": 0},
    "noclamp": {"clamp_indirect": 0.0},
}
CYCLES_VARIANTS: dict[str, dict[str, Any]] = {
    "bp": {},
    "direct": {"max_bounces": 0},
}
"""Cycles' counterparts (``scene.cycles`` attributes over BlenderProc's reference mode)."""


def srgb8(linear: np.ndarray) -> np.ndarray:
    from hybridgen.render.tonemap import to_srgb8

    return to_srgb8(np.asarray(linear, np.float32))


def scores(image: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    rel = float(np.mean((image - reference) ** 2 / (reference ** 2 + 1e-2)))
    return {"psnr": round(psnr(srgb8(image), srgb8(reference)), 2), "relmse": rel}


def hybridgen_linear(scene: Any, spp: int, seed: int, **settings: Any) -> tuple[np.ndarray, float]:
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

    watch = Stopwatch()
    view = PathTraceView(scene, PathTraceSettings(samples=spp, **settings))
    image = view.render(scene.camera.keypoints[0], seed=seed)
    return image.astype(np.float64), watch.read()[1]


def read_exr(path: Path) -> np.ndarray:
    import mitsuba as mi

    return np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="160x120")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--scenes", default="")
    parser.add_argument("--variants", default="default,bp")
    parser.add_argument("--no-cycles", action="store_true")
    parser.add_argument("--out", default=str(REPO / "output" / "color_decompose"))
    args = parser.parse_args()

    width, height = (int(v) for v in args.res.split("x"))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    python = None if args.no_cycles else ensure_bpy_venv(REPO / ".venv-bpy")
    for name in args.scenes.split(",") if args.scenes else SCENES:
        scene = build(name, width, height, out)
        row: dict[str, Any] = {"scene": name, "spp": args.spp}
        for variant in args.variants.split(","):
            settings = VARIANTS[variant]
            reference, _ = hybridgen_linear(scene, args.reference_spp, 12345, **settings)
            image, cpu = hybridgen_linear(scene, args.spp, 1, **settings)
            row[f"hg_{variant}"] = {**scores(image, reference), "cpu_s": round(cpu, 2)}
            np.save(out / f"{name}_hg_{variant}_ref.npy", reference.astype(np.float32))
            np.save(out / f"{name}_hg_{variant}_{args.spp}.npy", image.astype(np.float32))
        if python is not None:
            npz = out / f"{name}.npz"
            export_for_cycles(scene, npz, 1024, 3, 0)
            worker = CyclesWorker(python, npz)
            try:
                for variant in args.variants.split(","):
                    if variant not in CYCLES_VARIANTS:
                        continue
                    low = out / f"{name}_cycles_{variant}_{args.spp}.exr"
                    ref = out / f"{name}_cycles_{variant}_ref.exr"
                    extra = {"mode": "reference", "cycles": CYCLES_VARIANTS[variant]}
                    answer = worker.render(0, False, 1, low, spp=args.spp, **extra)
                    worker.render(0, False, 12345, ref, spp=args.reference_spp, **extra)
                    row[f"cycles_{variant}"] = {**scores(read_exr(low), read_exr(ref)),
                                                "cpu_s": round(answer["cpu_s"], 2)}
            finally:
                worker.close()
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    main()
