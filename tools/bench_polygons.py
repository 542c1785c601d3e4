"""COCO polygon tracer speed (hybridgen.io.mask_encoding.mask_to_polygons) on fragmented 640x480 masks.

Each mask's polygons are rasterized back with pycocotools and compared with the mask (holes filled, as
COCO polygons cannot have holes): the timing only counts if the output is exact.

    .venv/bin/python tools/bench_polygons.py                      # this checkout
    .venv/bin/python tools/bench_polygons.py --baseline 62b8561   # and the tracer of a git revision, same run

The baseline is read from ``git show REV:hybridgen/io/mask_encoding.py`` at run time (nothing copied).
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from harness import Stopwatch
from scipy import ndimage

REPO = Path(__file__).resolve().parents[1]


def masks() -> dict[str, np.ndarray]:
    """Fragmented 640x480 masks: many small blobs, a noisy segmentation edge, salt-and-pepper noise."""
    rng = np.random.default_rng(0)
    blobs = ndimage.gaussian_filter(rng.random((480, 640)), 2.0) > 0.52
    ragged = (ndimage.gaussian_filter(rng.random((480, 640)), 8) > 0.5) ^ (rng.random((480, 640)) < 0.05)
    return {"small blobs": blobs, "ragged segment": ragged, "noise 10%": rng.random((480, 640)) < 0.1}


def load_tracer(revision: str | None):
    if revision is None:
        from hybridgen.io import mask_encoding

        return mask_encoding.mask_to_polygons
    source = subprocess.run(["git", "-C", str(REPO), "show", f"{revision}:hybridgen/io/mask_encoding.py"],
                            check=True, capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / "baseline_mask_encoding.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("hybridgen.io._baseline_mask_encoding", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module.mask_to_polygons


def check(mask: np.ndarray, polygons: list[list[float]]) -> None:
    from pycocotools import mask as mask_utils

    height, width = mask.shape
    merged = mask_utils.merge(mask_utils.frPyObjects(polygons, height, width))
    filled = ndimage.binary_fill_holes(mask, np.ones((3, 3)))
    if not np.array_equal(mask_utils.decode(merged).astype(bool), filled):
        raise SystemExit("polygons do not rasterize back to the mask")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", help="git revision whose tracer to time in the same run")
    parser.add_argument("--repeat", type=int, default=3)
    ns = parser.parse_args()
    tracers = {"current": load_tracer(None)}
    if ns.baseline:
        tracers[f"baseline {ns.baseline}"] = load_tracer(ns.baseline)
    for name, mask in masks().items():
        for label, tracer in tracers.items():
            times = []
            for _ in range(ns.repeat if label == "current" else 1):
                watch = Stopwatch()
                polygons = tracer(mask)
                times.append(watch.read()[0])
            check(mask, polygons)
            print(f"{name:15s} {label:20s} {min(times):8.3f} s  {len(polygons):6d} polygons  "
                  f"{sum(len(p) for p in polygons) // 2:7d} corners  (exact)", flush=True)


if __name__ == "__main__":
    main()
