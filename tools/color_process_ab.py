"""Whole-process A/B of hybridgen's default color render: two source trees, alternating runs, warm caches.

Runs ``tools/default_color_process.py`` of each tree (``PYTHONPATH=<tree>``, the same ``.venv``) on the scenes of
tools/color_quality.py, each tree with its own Dr.Jit kernel cache and hybridgen cache (one warm-up run fills
them), then ``--runs`` timed runs per tree in ABBA order. Prints each run (wall and CPU seconds from spawn to exit,
the process's phases) and per scene the medians, the new/base ratios, whether both trees wrote the same PNG bytes
and how many kernels each tree compiled during its timed runs (a warm run should compile none: a compiled kernel
is a Dr.Jit kernel-cache miss, ~0.5 s of CPU per path kernel).

    git worktree add /tmp/base <commit> --detach
    .venv/bin/python tools/color_process_ab.py /tmp/base . --scenes tabletop,materials --runs 4
    .venv/bin/python tools/color_process_ab.py . . --base-args="--exit interpreter"   # one tree, two ways to end

The machine's load average is printed at start and end; on a shared machine compare CPU seconds and ratios.
"""
from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
import tempfile
from pathlib import Path
from typing import Any, Sequence

from harness import alternating, load_average, medians, run_process

PHASES = ("wall", "cpu", "start", "build", "render", "after")
"""Per run (s): spawn to exit, CPU (user + system of the child), spawn to ``import hybridgen`` done, the scene
build, ``render_color``, and from its end to the process's exit (PNG, interpreter shutdown)."""


def run_once(tree: Path, caches: Path, scene: str, resolution: str, png: Path,
             extra: Sequence[str] = ()) -> dict[str, float]:
    """One whole process of ``tree``'s tools/default_color_process.py (options ``extra``) with the caches under
    ``caches``."""
    env = {**os.environ, "PYTHONPATH": str(tree), "DRJIT_CACHE_DIR": str(caches / "drjit"),
           "HYBRIDGEN_CACHE_DIR": str(caches / "hybridgen")}
    env.setdefault("HYBRIDGEN_THREADS", "2")  # the 2 CPU threads
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # byte-compiled sources, as an installed package
    command = [sys.executable, str(tree / "tools" / "default_color_process.py"), scene, resolution, str(png),
               str(caches / "work"), *extra]
    (caches / "work").mkdir(parents=True, exist_ok=True)
    spawned = time.time()
    finished = run_process(command, env)
    marks = finished.report
    assert marks is not None, f"{command[1]} printed no report"
    return {"wall": finished.wall, "cpu": finished.cpu, "start": marks["imported"] - spawned,
            "build": marks["built"] - marks["imported"], "render": marks["rendered"] - marks["built"],
            "after": spawned + finished.wall - marks["rendered"]}


def kernel_count(caches: Path) -> int:
    """Compiled kernels in a Dr.Jit cache folder."""
    return len(list((caches / "drjit").glob("*.bin")))


def compare(trees: dict[str, Path], scene: str, resolution: str, runs: int, root: Path,
            extra: dict[str, Sequence[str]]) -> dict[str, Any]:
    """One scene: warm-up runs, then ``runs`` timed runs per tree (ABBA); medians and kernel-cache misses.
    ``extra``: the options each tree's process gets."""
    caches = {name: root / name for name in trees}
    pngs = {name: root / f"{scene}_{name}.png" for name in trees}
    for name, tree in trees.items():
        run_once(tree, caches[name], scene, resolution, pngs[name], extra[name])
    before = {name: kernel_count(caches[name]) for name in trees}
    timed: dict[str, list[dict[str, float]]] = {name: [] for name in trees}
    for index in range(runs):
        for name in alternating(list(trees), index):
            row = run_once(trees[name], caches[name], scene, resolution, pngs[name], extra[name])
            timed[name].append(row)
            print(f"{scene} {name}: " + " ".join(f"{key} {row[key]:.2f}" for key in PHASES), flush=True)
    middle = {name: medians(rows) for name, rows in timed.items()}
    return {"scene": scene, "medians": middle,
            "ratio_wall": middle["new"]["wall"] / middle["base"]["wall"],
            "ratio_cpu": middle["new"]["cpu"] / middle["base"]["cpu"],
            "same_bytes": pngs["base"].read_bytes() == pngs["new"].read_bytes(),
            "kernels_compiled_in_timed_runs": {name: kernel_count(caches[name]) - before[name] for name in trees}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", type=Path, help="source tree of the baseline (e.g. a git worktree)")
    parser.add_argument("new", type=Path, help="source tree to compare (e.g. .)")
    parser.add_argument("--scenes", default="tabletop,materials,window_room,hdri_tabletop")
    parser.add_argument("--runs", type=int, default=3, help="timed runs per tree and scene")
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--base-args", default="", help="options of base's default_color_process.py runs")
    parser.add_argument("--new-args", default="", help="options of new's default_color_process.py runs")
    args = parser.parse_args()
    extra = {"base": shlex.split(args.base_args), "new": shlex.split(args.new_args)}
    trees = {"base": args.base.resolve(), "new": args.new.resolve()}
    print(f"load average {load_average():.2f} at start; {os.cpu_count()} cores", flush=True)
    with tempfile.TemporaryDirectory(prefix="color_process_ab_") as root:
        for scene in args.scenes.split(","):
            result = compare(trees, scene, args.res, args.runs, Path(root) / scene, extra)
            line = " | ".join(f"{name}: " + " ".join(f"{key} {value:.2f}" for key, value in m.items())
                              for name, m in result["medians"].items())
            print(f"{scene} medians of {args.runs}: {line} | new/base wall {result['ratio_wall']:.3f} cpu "
                  f"{result['ratio_cpu']:.3f} | same bytes {result['same_bytes']} | kernels compiled in timed runs "
                  f"{result['kernels_compiled_in_timed_runs']}", flush=True)
    print(f"load average {load_average():.2f} at the end", flush=True)


if __name__ == "__main__":
    main()
