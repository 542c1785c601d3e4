"""Throughput of sharded runs with 1 and 2 workers, on the process pool and on Ray, for a labels-only and a
color config (each worker gets cores / workers threads for llvmpipe and Dr.Jit).

Run: .venv/bin/python tools/bench_workers.py [--scenes 8] [--no-ray]
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

CONFIG = """
global: {{all: {{output_dir: "<args:0>"}}}}
modules:
  - name: main.Initializer
    config: {{seed: 1, number_of_scenes: {scenes}}}
  - name: loader.ObjLoader
    config: {{path: {repo}/configs/assets/knot.obj, name: knot, category_id: 2, scale: 0.3,
             location: {{provider: sampler.Uniform3d, min: [-0.5, -0.5, 0.6], max: [0.5, 0.5, 0.9]}}}}
  - name: loader.PrimitiveLoader
    config: {{shape: plane, size: 8, name: floor, category_id: 1}}
  - name: camera.CameraSampler
    config:
      intrinsics: {{resolution_x: {width}, resolution_y: {height}}}
      cam_poses:
        - number_of_samples: {keypoints}
          location: {{provider: sampler.Shell, center: [0, 0, 0], radius_min: 2, radius_max: 4, elevation_min: 20,
                     elevation_max: 70}}
          rotation: {{format: look_at, value: {{provider: getter.POI, selector: {{name: knot}}}}}}
  - name: {renderer}
    config: {renderer_config}
  - name: writer.Hdf5Writer
"""

KINDS = {
    "labels": dict(renderer="renderer.SegMapRenderer", renderer_config="{render_distance: true}", width=640,
                   height=480, keypoints=60),
    "color": dict(renderer="renderer.RgbRenderer", renderer_config="{samples: 16, max_bounces: 3, render_depth: true}",
                  width=320, height=240, keypoints=6),
}


def timed_run(config: Path, out: Path, *extra: str) -> float:
    shutil.rmtree(out, ignore_errors=True)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(out), *extra],
                          capture_output=True, text=True, cwd=REPO)
    if done.returncode != 0:
        raise SystemExit(done.stderr[-2000:])
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=6)
    parser.add_argument("--no-ray", action="store_true")
    args = parser.parse_args()
    executors = [("pool", [])] + ([] if args.no_ray else [("ray", ["--executor", "ray"])])
    with tempfile.TemporaryDirectory() as tmp:
        for kind, values in KINDS.items():
            config = Path(tmp) / f"{kind}.yaml"
            config.write_text(CONFIG.format(scenes=args.scenes, repo=REPO, **values))
            keypoints = args.scenes * values["keypoints"]
            for name, extra in executors:
                one = timed_run(config, Path(tmp) / "out", *extra, "--workers", "1")
                two = timed_run(config, Path(tmp) / "out", *extra, "--workers", "2")
                print(f"{kind:<6} {name:<4} 1 worker {keypoints / one:6.2f} kp/s ({one:5.1f} s)   2 workers "
                      f"{keypoints / two:6.2f} kp/s ({two:5.1f} s)   speed-up {one / two:.2f}x", flush=True)


if __name__ == "__main__":
    main()
