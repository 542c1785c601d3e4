"""Blender's procedural textures against hybridgen's (hybridgen/scene/procedural_texture.py): statistics of the
value a Displace modifier reads (mean, standard deviation, 1 % / 99 % quantiles, min, max) over random points,
and its correlation at shifts along x - so "range 0..1" and "feature size = noise_scale" are measured, not assumed.

    .venv/bin/python tools/blender_textures.py [--points 3000] [--json OUT.json]

Blender's side runs in the bpy 4.2 venv (``.venv-bpy``, or ``$HYBRIDGEN_BPY_PYTHON``): this file re-runs itself
there with ``--blender`` and evaluates ``bpy.data.textures.new(name, type).evaluate(point)`` (the 4th component,
which is what the Displace modifier reads: the intensity, or the mean of R, G, B for color textures). Both sides
use the same points (seeded, uniform in [-12, 12]^3). BLEND is exact in hybridgen; the others match in statistics,
not value for value. docs/blenderproc.md records a run.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
LAGS = (0.05, 0.1, 0.2, 0.3, 0.5)
CASES: list[tuple[str, str, dict]] = [
    ("CLOUDS", "CLOUDS", {}),
    ("CLOUDS scale 1 depth 0", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0}),
    ("CLOUDS scale 1 depth 0 hard", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0, "noise_type": "HARD_NOISE"}),
    ("CLOUDS scale 1 depth 0 perlin", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0,
                                                 "noise_basis": "IMPROVED_PERLIN"}),
    ("CLOUDS scale 1 depth 0 F1", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0, "noise_basis": "VORONOI_F1"}),
    ("CLOUDS scale 1 depth 0 F2-F1", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0,
                                               "noise_basis": "VORONOI_F2_F1"}),
    ("CLOUDS scale 1 depth 0 crackle", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0,
                                                 "noise_basis": "VORONOI_CRACKLE"}),
    ("CLOUDS scale 1 depth 0 cell", "CLOUDS", {"noise_scale": 1.0, "noise_depth": 0, "noise_basis": "CELL_NOISE"}),
    ("CLOUDS color", "CLOUDS", {"cloud_type": "COLOR"}),
    ("CLOUDS bright 1.3 contrast 2", "CLOUDS", {"intensity": 1.3, "contrast": 2.0}),
    ("DISTORTED_NOISE", "DISTORTED_NOISE", {}),
    ("DISTORTED_NOISE distortion 3", "DISTORTED_NOISE", {"distortion": 3.0}),
    ("MAGIC", "MAGIC", {}),
    ("MAGIC depth 0", "MAGIC", {"noise_depth": 0}),
    ("MARBLE", "MARBLE", {}),
    ("MARBLE sharper", "MARBLE", {"marble_type": "SHARPER"}),
    ("MUSGRAVE", "MUSGRAVE", {}),
    ("MUSGRAVE fbm", "MUSGRAVE", {"musgrave_type": "FBM"}),
    ("MUSGRAVE ridged", "MUSGRAVE", {"musgrave_type": "RIDGED_MULTIFRACTAL"}),
    ("MUSGRAVE hybrid", "MUSGRAVE", {"musgrave_type": "HYBRID_MULTIFRACTAL"}),
    ("MUSGRAVE hetero", "MUSGRAVE", {"musgrave_type": "HETERO_TERRAIN"}),
    ("NOISE", "NOISE", {}),
    ("STUCCI", "STUCCI", {}),
    ("VORONOI", "VORONOI", {}),
    ("VORONOI manhattan", "VORONOI", {"distance_metric": "MANHATTAN"}),
    ("WOOD", "WOOD", {}),
    ("WOOD ringnoise", "WOOD", {"wood_type": "RINGNOISE"}),
    ("BLEND", "BLEND", {}),
    ("BLEND radial", "BLEND", {"progression": "RADIAL"}),
]
"""(label, Blender type, settings changed from the defaults)."""


def points(count: int) -> np.ndarray:
    return np.random.default_rng(1).uniform(-12.0, 12.0, size=(count, 3))


def statistics(evaluate, pts: np.ndarray) -> dict:
    """The statistics of ``evaluate(points) -> values`` (module doc)."""
    values = evaluate(pts)
    corr = [float(np.corrcoef(values, evaluate(pts + np.array([lag, 0.0, 0.0])))[0, 1]) for lag in LAGS]
    q = np.quantile(values, [0.0, 0.01, 0.99, 1.0])
    return {"mean": float(values.mean()), "std": float(values.std()), "min": float(q[0]), "q01": float(q[1]),
            "q99": float(q[2]), "max": float(q[3]), "corr": corr}


def blender_side(count: int) -> dict:
    import bpy  # type: ignore[import-not-found]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    out = {}
    for label, kind, changes in CASES:
        texture = bpy.data.textures.new(label, kind)
        for key, value in changes.items():
            setattr(texture, key, value)
        out[label] = statistics(lambda p: np.array([texture.evaluate(tuple(x))[3] for x in p]), points(count))
    return out


def hybridgen_side(count: int) -> dict:
    sys.path.insert(0, str(REPO))
    from hybridgen.scene.procedural_texture import displacement_value, settings_of

    out = {}
    for label, kind, changes in CASES:
        settings = {**settings_of(kind), **changes}
        out[label] = statistics(lambda p: displacement_value(kind, settings, p), points(count))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=3000)
    parser.add_argument("--blender", action="store_true", help="(internal) measure Blender, print JSON")
    parser.add_argument("--json", type=Path, help="write both sides' statistics here")
    args = parser.parse_args()
    if args.blender:
        print(json.dumps(blender_side(args.points)))
        return 0
    python = Path(os.environ.get("HYBRIDGEN_BPY_PYTHON", REPO / ".venv-bpy" / "bin" / "python"))
    if not python.is_file():
        print(f"no bpy venv at {python}: create one with bpy==4.2.0 and numpy<2 (see tools/cycles_worker.py)")
        return 2
    done = subprocess.run([str(python), __file__, "--blender", "--points", str(args.points)], capture_output=True,
                          text=True, timeout=1800)
    if done.returncode != 0:
        print(done.stderr[-2000:])
        return 1
    blender = json.loads(done.stdout.strip().splitlines()[-1])
    ours = hybridgen_side(args.points)
    print(f"{'texture':32s} {'engine':9s} {'mean':>7s} {'std':>7s} {'q01':>7s} {'q99':>7s} {'min':>7s} {'max':>7s}  "
          f"corr at x + {', '.join(str(lag) for lag in LAGS)}")
    for label, _, _ in CASES:
        for engine, table in (("Blender", blender), ("hybridgen", ours)):
            s = table[label]
            print(f"{label:32s} {engine:9s} {s['mean']:7.3f} {s['std']:7.3f} {s['q01']:7.3f} {s['q99']:7.3f} "
                  f"{s['min']:7.3f} {s['max']:7.3f}  {' '.join(f'{c:6.3f}' for c in s['corr'])}")
    if args.json:
        args.json.write_text(json.dumps({"blender": blender, "hybridgen": ours}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
