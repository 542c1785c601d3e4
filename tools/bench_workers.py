"""Throughput of sharded runs with 1 and 2 workers, on the process pool and on Ray, for a labels-only and a
color config (each worker gets cores / workers threads for llvmpipe and Dr.Jit).

Run: .venv/bin/python tools/bench_workers.py [--scenes 8] [--no-ray]
"""
from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

from harness import run_process
from scene_yaml import KINDS, knot_config

REPO = Path(__file__).resolve().parents[1]


def timed_run(config: Path, out: Path, *extra: str) -> float:
    """Wall seconds of one whole ``hybridgen run`` of ``config`` into ``out`` (emptied first)."""
    shutil.rmtree(out, ignore_errors=True)
    return run_process([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(out), *extra],
                       cwd=REPO).wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=6)
    parser.add_argument("--no-ray", action="store_true")
    args = parser.parse_args()
    executors = [("pool", [])] + ([] if args.no_ray else [("ray", ["--executor", "ray"])])
    with tempfile.TemporaryDirectory() as tmp:
        for kind, values in KINDS.items():
            config = Path(tmp) / f"{kind}.yaml"
            config.write_text(knot_config(kind, args.scenes))
            keypoints = args.scenes * values["keypoints"]
            for name, extra in executors:
                one = timed_run(config, Path(tmp) / "out", *extra, "--workers", "1")
                two = timed_run(config, Path(tmp) / "out", *extra, "--workers", "2")
                print(f"{kind:<6} {name:<4} 1 worker {keypoints / one:6.2f} kp/s ({one:5.1f} s)   2 workers "
                      f"{keypoints / two:6.2f} kp/s ({two:5.1f} s)   speed-up {one / two:.2f}x", flush=True)


if __name__ == "__main__":
    main()
