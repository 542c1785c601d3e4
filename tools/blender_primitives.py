"""Blender 4.2's mesh primitives (``bpy.ops.mesh.primitive_*_add``, what BlenderProc's ``create_primitive`` calls)
measured with bpy beside hybridgen's (hybridgen/scene/blender_primitives.py): positions, polygons with their corner
order, per-corner UVs.

    .venv/bin/python tools/blender_primitives.py [--store tests/scene/data/blender_primitives.json]

Blender's side runs in a bpy 4.2 venv (``$HYBRIDGEN_BPY_PYTHON``, else ``.venv-bpy`` or ``.venv-blenderproc``,
the first with bpy; this file re-runs itself there with ``--blender``). For each case (:data:`CASES`: Blender's
defaults and other segment counts, radii, depths and cap fills) it prints the vertex and polygon counts of both,
whether every Blender polygon has a hybridgen polygon with the same corners in the same order (positions within
1e-5 m), the largest UV difference over all corners, and whether the vertex and polygon order are Blender's too.
``--store`` writes per case the counts and every polygon (at most :data:`STORED_POLYGONS`, spread over the list)
with its corner positions and UVs: the table tests/scene/test_blender_primitives.py checks hybridgen against.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CASES: list[tuple[str, str, dict[str, Any]]] = [
    ("cube", "cube", {}), ("cube 0.5", "cube", {"size": 0.5}), ("plane", "plane", {}),
    ("plane 3", "plane", {"size": 3.0}), ("uv_sphere", "uv_sphere", {}),
    ("uv_sphere 6x4 r2", "uv_sphere", {"segments": 6, "ring_count": 4, "radius": 2.0}),
    ("uv_sphere 8x5", "uv_sphere", {"segments": 8, "ring_count": 5}),
    ("uv_sphere 12x7", "uv_sphere", {"segments": 12, "ring_count": 7, "radius": 0.3}),
    ("uv_sphere 5x3", "uv_sphere", {"segments": 5, "ring_count": 3}),
    ("uv_sphere 64x32", "uv_sphere", {"segments": 64, "ring_count": 32}),
    ("cylinder", "cylinder", {}), ("cylinder 6 r0.5 d3", "cylinder", {"vertices": 6, "radius": 0.5, "depth": 3.0}),
    ("cylinder 3", "cylinder", {"vertices": 3}), ("cylinder 5 trifan", "cylinder", {"vertices": 5, "end_fill_type": "TRIFAN"}),
    ("cylinder 7 nothing", "cylinder", {"vertices": 7, "end_fill_type": "NOTHING"}),
    ("cone", "cone", {}), ("cone 6 r0.5 d3", "cone", {"vertices": 6, "radius1": 0.5, "depth": 3.0}),
    ("cone 4", "cone", {"vertices": 4}), ("cone 5 trifan", "cone", {"vertices": 5, "end_fill_type": "TRIFAN"}),
    ("cone 7 nothing", "cone", {"vertices": 7, "end_fill_type": "NOTHING"}),
    ("cone 6 r2 0.4", "cone", {"vertices": 6, "radius1": 1.2, "radius2": 0.4}),
    ("cone 5 r2 trifan", "cone", {"vertices": 5, "radius2": 0.5, "end_fill_type": "TRIFAN"}),
    ("cone 5 r2 nothing", "cone", {"vertices": 5, "radius2": 0.5, "end_fill_type": "NOTHING"}),
]
"""(name, primitive, operator arguments); ``uv_sphere`` is ``primitive_uv_sphere_add``, the others
``primitive_<name>_add``."""
STORED_POLYGONS = 40


def blender_side() -> dict[str, Any]:
    import bpy  # type: ignore[import-not-found]

    out: dict[str, Any] = {}
    for name, kind, arguments in CASES:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        getattr(bpy.ops.mesh, f"primitive_{kind}_add")(**arguments)
        mesh = bpy.context.object.data
        uv = mesh.uv_layers.active.data
        out[name] = {"positions": [list(v.co) for v in mesh.vertices],
                     "polygons": [list(p.vertices) for p in mesh.polygons],
                     "uvs": [list(uv[i].uv) for p in mesh.polygons for i in p.loop_indices],
                     "smooth": any(p.use_smooth for p in mesh.polygons)}
    return out


def hybridgen_mesh(kind: str, arguments: dict[str, Any]) -> Any:
    from hybridgen.scene import blender_primitives

    return getattr(blender_primitives, kind)(**arguments)


def _polygons(positions: np.ndarray, corners: np.ndarray, starts: np.ndarray) -> list[np.ndarray]:
    return [positions[corners[a:b]] for a, b in zip(starts[:-1], starts[1:])]


def matching_polygon(corners: np.ndarray, polygons: list[np.ndarray], tolerance: float = 1e-5) -> int | None:
    """The index of the polygon of ``polygons`` with ``corners`` (positions, m) in the same order, else None."""
    for j, other in enumerate(polygons):
        if other.shape == corners.shape and np.abs(other - corners).max() <= tolerance:
            return j
    return None


def compare(measured: dict[str, Any], ours: Any) -> dict[str, Any]:
    """Counts, polygon matching and the largest UV difference of one case."""
    theirs_positions = np.asarray(measured["positions"])
    sizes = [len(p) for p in measured["polygons"]]
    theirs_starts = np.concatenate([[0], np.cumsum(sizes)])
    theirs = _polygons(theirs_positions, np.concatenate(measured["polygons"]), theirs_starts)
    mine = _polygons(ours.positions, ours.corners, ours.starts)
    uv_theirs, uv_mine = np.asarray(measured["uvs"]), ours.attributes["uvs"]
    found, worst = 0, 0.0
    for p, corners in enumerate(theirs):
        j = matching_polygon(corners, mine)
        if j is None:
            continue
        found += 1
        worst = max(worst, float(np.abs(uv_theirs[theirs_starts[p]:theirs_starts[p + 1]]
                                        - uv_mine[ours.starts[j]:ours.starts[j + 1]]).max()))
    same_order = (len(theirs_positions) == len(ours.positions) and np.allclose(theirs_positions, ours.positions, atol=1e-5)
                  and sizes == list(np.diff(ours.starts)) and np.array_equal(np.concatenate(measured["polygons"]), ours.corners))
    return {"vertices": (len(theirs_positions), len(ours.positions)), "polygons": (len(theirs), len(mine)),
            "matched": found, "uv": worst, "order": bool(same_order)}


def stored_case(measured: dict[str, Any]) -> dict[str, Any]:
    """Counts and a spread of polygons (corner positions, UVs) of one measured case."""
    positions, polygons, uvs = np.asarray(measured["positions"]), measured["polygons"], np.asarray(measured["uvs"])
    starts = np.concatenate([[0], np.cumsum([len(p) for p in polygons])])
    chosen = np.unique(np.linspace(0, len(polygons) - 1, min(STORED_POLYGONS, len(polygons))).round().astype(int))
    return {"vertices": len(positions), "polygons": len(polygons),
            "sample": [{"corners": np.round(positions[polygons[p]], 6).tolist(),
                        "uvs": np.round(uvs[starts[p]:starts[p + 1]], 6).tolist()} for p in chosen]}


def bpy_python() -> Path:
    """The first Python with bpy among $HYBRIDGEN_BPY_PYTHON, .venv-bpy, .venv-blenderproc."""
    candidates = [os.environ.get("HYBRIDGEN_BPY_PYTHON")] + [str(REPO / v / "bin" / "python")
                                                             for v in (".venv-bpy", ".venv-blenderproc")]
    for candidate in filter(None, candidates):
        if Path(candidate).exists() and subprocess.run([candidate, "-c", "import bpy"],
                                                       capture_output=True).returncode == 0:
            return Path(candidate)
    raise SystemExit("no Python with bpy 4.2: set HYBRIDGEN_BPY_PYTHON or make .venv-blenderproc "
                     "(tools/blenderproc_reference.py setup)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blender", type=Path, help=argparse.SUPPRESS)  # internal: run inside bpy, write here
    parser.add_argument("--store", type=Path, default=None, help="write the measured table for the tests")
    ns = parser.parse_args()
    if ns.blender:
        ns.blender.write_text(json.dumps(blender_side()))
        sys.stdout.flush()
        os._exit(0)  # bpy 4.2 can crash while the interpreter shuts down
    out = REPO / ".blender_primitives.json"
    done = subprocess.run([str(bpy_python()), __file__, "--blender", str(out)], capture_output=True, text=True)
    if not out.exists():
        raise SystemExit(f"bpy failed: {(done.stderr or done.stdout).strip().splitlines()[-3:]}")
    measured = json.loads(out.read_text())
    out.unlink()
    print(f"{'case':22s} {'vertices B/h':>13s} {'polygons B/h':>13s} {'matched':>8s} {'max |du|':>9s}  order")
    for name, kind, arguments in CASES:
        row = compare(measured[name], hybridgen_mesh(kind, arguments))
        print(f"{name:22s} {'%d / %d' % row['vertices']:>13s} {'%d / %d' % row['polygons']:>13s} "
              f"{row['matched']:8d} {row['uv']:9.1e}  {'Blender' if row['order'] else 'own'}"
              f"{'  (smooth in Blender!)' if measured[name]['smooth'] else ''}")
    if ns.store:
        lines = [f"{json.dumps(name)}: {json.dumps({'kind': kind, 'arguments': arguments, **stored_case(measured[name])})}"
                 for name, kind, arguments in CASES]  # one case per line
        ns.store.write_text("{\n" + ",\n".join(lines) + "\n}\n")
        print(f"stored {ns.store}")


if __name__ == "__main__":
    main()
