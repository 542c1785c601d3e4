"""One scene of tools/color_quality.py rendered with hybridgen's default color, as a whole user process.

Run by tools/bench_color_quality.py and tools/color_process_ab.py
(``.venv/bin/python tools/default_color_process.py SCENE WxH OUT.png WORKDIR``), which
times this process from spawn to exit, wall clock and CPU (its rusage, children included): Python's start,
``import hybridgen``, building the scene (meshes read through hybridgen's loaders), Mitsuba's start and the
variant probe, kernels (from the Dr.Jit cache the parent points ``DRJIT_CACHE_DIR`` at), raster guides, the
adaptive render, denoising and writing the PNG - what a user's script pays for one frame with no color options
(``render_color(scene, sinks, PathTraceSettings(), denoise=True)``, as ``renderer.RgbRenderer``'s defaults).

Prints one JSON line: epoch seconds at this script's first line (``started``), after ``import hybridgen``
(``imported``), after the scene is built (``built``), after ``render_color`` (``rendered``), after the PNG
is written (``written``), and the mean samples per pixel (``mean_spp``).

The process then ends as the ``hybridgen`` command ends a successful run (:func:`hybridgen.process_exit.end_process`:
atexit handlers, flushed streams, no interpreter teardown; ``--exit interpreter``: Python's normal shutdown, 0.1-0.2 s
more).
"""
from __future__ import annotations

import time

STARTED = time.time()

import argparse  # noqa: E402
import json  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from color_lobes import LOBES  # noqa: E402  (imports nothing: the startup phase stays Python's own)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="a scene name of tools/color_quality.py")
    parser.add_argument("res", help="WxH")
    parser.add_argument("png", type=Path, help="where the sRGB frame goes")
    parser.add_argument("workdir", type=Path, help="folder for generated scene inputs (the HDRI)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threshold", type=float, default=None, help="noise threshold (default: hybridgen's)")
    parser.add_argument("--max-samples", type=int, default=None,
                        help="most samples per pixel, adaptive at the threshold (default: hybridgen's)")
    parser.add_argument("--lobes", choices=sorted(LOBES), default="default")
    parser.add_argument("--exit", choices=("command", "interpreter"), default="command",
                        help="end as the hybridgen command does (default) or through Python's normal shutdown")
    args = parser.parse_args()
    marks = {"started": STARTED}

    import hybridgen as hg

    marks["imported"] = time.time()
    import color_quality

    width, height = (int(v) for v in args.res.lower().split("x"))
    scene = color_quality.build(args.scene, width, height, args.workdir)
    marks["built"] = time.time()
    sink = hg.MemorySink()
    sampling: dict[str, Any] = {"noise_threshold": args.threshold}
    if args.max_samples is not None:  # samples with a threshold is a maximum (without one, a fixed count)
        from hybridgen.render.pathtrace.path_trace import DEFAULT_NOISE_THRESHOLD

        sampling = {"samples": args.max_samples,
                    "noise_threshold": DEFAULT_NOISE_THRESHOLD if args.threshold is None else args.threshold}
    hg.render_color(scene, [sink], hg.PathTraceSettings(**sampling, **LOBES[args.lobes]),
                    seed=args.seed, denoise=True, sample_counts=True)
    marks["rendered"] = time.time()
    from PIL import Image

    frame = sink.frames[0]
    partial = args.png.with_name(args.png.name + ".incomplete")
    Image.fromarray(frame["colors"]).save(partial, format="PNG")
    partial.replace(args.png)
    marks["written"] = time.time()
    print(json.dumps({**marks, "mean_spp": float(frame["sample_counts"].mean())}), flush=True)
    if args.exit == "command":
        from hybridgen.process_exit import end_process

        end_process(0)


if __name__ == "__main__":
    main()
