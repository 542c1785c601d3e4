"""Long-run memory check: render many label keypoints (and color keypoints) in one process, writing HDF5,
and report resident memory; fail when it grows by more than the limit after warm-up.

Run: .venv/bin/python tools/soak.py [--labels 10000] [--color 500] [--res 320x240] [--limit-mb 50]
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from harness import rss_mib


def soak_scene(width: int, height: int, keypoints: int):  # type: ignore[no-untyped-def]
    import hybridgen as hg

    rng = np.random.default_rng(0)
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 8.0, name="floor", category_id=1))
    for i in range(12):
        pose = hg.object_pose([*rng.uniform(-2, 2, 2), 0.3], [0, 0, rng.uniform(0, 6)])
        scene.add(hg.make_primitive(["sphere", "cube", "torus", "cone"][i % 4], 0.6, name=f"o{i}",
                                    category_id=2 + i % 3, local2world=pose))
    scene.lights.append(hg.Light("sun", "SUN", energy=2.0, local2world=hg.object_pose([0, 0, 5], [0.4, 0.2, 0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.0, width, height)
    for i in range(keypoints):
        angle = 2 * math.pi * i / 97.0
        scene.camera.add_keypoint(hg.look_at([4 * math.cos(angle), 4 * math.sin(angle), 2 + math.sin(i)], [0, 0, 0.3]))
    return scene


class MemoryCurve:
    """A progress 'bar' that samples RSS every ``every`` keypoints."""

    def __init__(self, every: int) -> None:
        self.every, self.count, self.samples = every, 0, []  # type: ignore[var-annotated]

    def __call__(self, total: int, what: str) -> "MemoryCurve":
        self.count, self.what = 0, what
        return self

    def update(self, n: int) -> None:
        self.count += n
        if self.count % self.every == 0:
            self.samples.append((self.what, self.count, rss_mib()[0]))

    def close(self) -> None:
        pass


def run(labels: int, color: int, width: int, height: int, every: int) -> list[tuple[str, int, float]]:
    """Render, write, and return the (pass, keypoints done, RSS MB) samples."""
    import hybridgen as hg
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings
    from hybridgen.render.render_color import render_color

    curve = MemoryCurve(every)
    with tempfile.TemporaryDirectory() as tmp:
        if labels:
            scene = soak_scene(width, height, labels)
            writer = hg.Hdf5SingleFileWriter(Path(tmp) / "labels.hdf5")
            hg.render_labels(scene, [writer], hg.LabelRequest(distance=True, map_by=["class", "instance"]),
                             progress=curve)
            writer.finalize()
        if color:
            scene = soak_scene(width, height, color)
            writer = hg.Hdf5SingleFileWriter(Path(tmp) / "color.hdf5")
            render_color(scene, [writer], PathTraceSettings(samples=4, max_bounces=2),
                         labels=hg.LabelRequest(map_by=["instance"]), progress=curve)
            writer.finalize()
    return curve.samples


def growth(samples: list[tuple[str, int, float]], warmup: int) -> dict[str, float]:
    """Per pass: RSS growth (MB) from the first sample after ``warmup`` keypoints to the last."""
    out = {}
    for what in dict.fromkeys(s[0] for s in samples):
        mine = [s for s in samples if s[0] == what and s[1] >= warmup] or [s for s in samples if s[0] == what]
        out[what] = mine[-1][2] - mine[0][2]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=int, default=10000)
    parser.add_argument("--color", type=int, default=500)
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--every", type=int, default=250, help="keypoints between memory samples")
    parser.add_argument("--limit-mb", type=float, default=50.0)
    args = parser.parse_args()
    width, height = (int(v) for v in args.res.split("x"))
    start = time.perf_counter()
    samples = run(args.labels, args.color, width, height, args.every)
    for what, count, mb in samples:
        print(f"{what:>6} {count:>6} keypoints  RSS {mb:8.1f} MB")
    grown = growth(samples, warmup=min(1000, args.labels // 5))
    print(f"{time.perf_counter() - start:.0f} s; growth after warm-up: "
          + ", ".join(f"{k} {v:+.1f} MB" for k, v in grown.items()))
    sys.exit(0 if all(v <= args.limit_mb for v in grown.values()) else 1)


if __name__ == "__main__":
    main()
