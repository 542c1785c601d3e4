"""Throughput of hybridgen.data: the reader (samples/s over a single file, a sharded index and the
BlenderProc layout of 320x240 images: every key, and colors + depth + ids) and the on-the-fly generator
(samples/s per worker, labels only and with color, 1 and 2 workers). Numbers depend on machine load;
compare rows of one run.

    .venv/bin/python tools/bench_data.py [--scenes 4]
"""
from __future__ import annotations

import argparse
import multiprocessing
import tempfile
from pathlib import Path

from harness import Stopwatch
from scene_yaml import shell_cameras

CONFIG = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 1, number_of_scenes: %(scenes)d}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.8, name: box, category_id: 2,
             location: {provider: sampler.Uniform3d, min: [-1, -1, 0.4], max: [1, 1, 0.4]}}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.6, name: ball, category_id: 3, location: [0.9, 0.7, 0.3]}
  - name: lighting.LightLoader
    config: {lights: [{type: SUN, name: sun, energy: 2, rotation: [0.5, 0.2, 0.3]}]}
""" + shell_cameras(width=320, height=240, count=8, fov=1.0, radius=(3, 5), look_at="[0, 0, 0.3]") + """
  - name: renderer.RgbRenderer
    config: {samples: 4, max_bounces: 2, render_depth: true, render_distance: true, render_normals: true,
             map_by: [class, instance]}
  - name: writer.Hdf5Writer
    config: {layout: %(layout)s}
"""


def _reader_rate(source: Path, keys: list[str] | None = None) -> tuple[int, float]:
    from hybridgen.data import KeypointDataset

    data = KeypointDataset(source, keys=keys)
    watch = Stopwatch()
    count = sum(1 for _ in data)
    return count, count / watch.read()[0]


def _worker(config: str, scenes: int, color: bool, worker: int, workers: int, queue) -> None:
    from hybridgen.data import GeneratorDataset

    data = GeneratorDataset(config, ["/nonexistent"], scenes=scenes, color=color)
    watch = Stopwatch()
    count = sum(1 for _ in data.samples(worker, workers))
    queue.put((count, watch.read()[0]))


def _generator_rate(config: str, scenes: int, color: bool, workers: int) -> tuple[int, float, float]:
    """(samples, samples/s per worker, samples/s in all) with ``workers`` spawned processes."""
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    watch = Stopwatch()
    processes = [context.Process(target=_worker, args=(config, scenes, color, w, workers, queue))
                 for w in range(workers)]
    for p in processes:
        p.start()
    results = [queue.get() for _ in processes]
    for p in processes:
        p.join()
    total = sum(c for c, _ in results)
    per_worker = sum(c / s for c, s in results) / workers
    return total, per_worker, total / watch.read()[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=4)
    ns = parser.parse_args()
    import hybridgen as hg

    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        configs = {}
        for name, scenes, layout in (("single", 1, "single"), ("sharded", ns.scenes, "single"),
                                     ("blenderproc", 1, "blenderproc")):
            configs[name] = root / f"{name}.yaml"
            configs[name].write_text(CONFIG % {"scenes": scenes, "layout": layout})
            hg.run_config(configs[name], [str(root / name)])
        print("reader (320x240, as written by default):")
        for name in ("single", "sharded", "blenderproc"):
            for keys in (None, ["colors", "depth", "instance_segmaps"]):
                count, rate = _reader_rate(root / name, keys)
                print(f"  {name:12s} {'every key' if keys is None else ', '.join(keys):36s} {count:3d} samples "
                      f"{rate:8.1f} samples/s")
        print(f"generator ({ns.scenes} scenes x 8 keypoints, 320x240; spawned workers, per worker: startup not "
              "counted):")
        for color in (False, True):
            for workers in (1, 2):
                total, per_worker, overall = _generator_rate(str(configs["sharded"]), ns.scenes, color, workers)
                print(f"  {'color+labels' if color else 'labels only':12s} workers={workers}  {total:3d} samples  "
                      f"{per_worker:7.2f} samples/s per worker  {overall:7.2f} samples/s overall (with startup)")


if __name__ == "__main__":
    main()
