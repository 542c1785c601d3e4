"""Time per sample of hybridgen's two principled models on a color benchmark scene (tools/color_quality.py).

Run through tools/principled_vs_cycles.py::

    .venv/bin/python tools/principled_vs_cycles.py --time-scene tabletop --res 160x120 --spp 128 --repeats 10
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def time_per_sample(scene_name: str, res: tuple[int, int], spp: int, repeats: int) -> None:
    """Seconds per sample (whole frame) of the color benchmark's scene ``scene_name`` (tools/color_quality.py)
    with each principled model, hybridgen's default settings at a fixed ``spp``, alternating the models
    ``repeats`` times (after one warm-up render each); prints each run and the medians."""
    import statistics
    import time

    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.pathtrace.path_trace_settings import PathTraceSettings
    from hybridgen.render.pathtrace.principled_material import ENV_VARIABLE

    sys.path.insert(0, str(REPO / "tools"))
    from color_quality import build

    with tempfile.TemporaryDirectory() as tmp:
        scene = build(scene_name, *res, Path(tmp))
        views = {}
        for model in ("mitsuba", "blender"):
            os.environ[ENV_VARIABLE] = model
            views[model] = PathTraceView(scene, PathTraceSettings(samples=spp), variant="llvm_ad_rgb")
            views[model].render(scene.camera.keypoints[0], seed=99, spp=spp)
        times: dict[str, list[float]] = {"mitsuba": [], "blender": []}
        for repeat in range(repeats):
            for model in (("mitsuba", "blender") if repeat % 2 == 0 else ("blender", "mitsuba")):
                start = time.perf_counter()
                views[model].render(scene.camera.keypoints[0], seed=repeat, spp=spp)
                times[model].append((time.perf_counter() - start) / spp)
    for model, values in times.items():
        print(f"{scene_name} {res[0]}x{res[1]} {model}: " + " ".join(f"{v * 1e3:.2f}" for v in values)
              + f" ms/sample, median {statistics.median(values) * 1e3:.2f}")
    ratio = statistics.median(times["blender"]) / statistics.median(times["mitsuba"])
    print(f"time per sample, hybridgen Principled / Mitsuba principled: {ratio:.3f}")
