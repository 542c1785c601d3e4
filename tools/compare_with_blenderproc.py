"""The same BlenderProc 2 example script through the real BlenderProc and through ``hybridgen run``, outputs
compared: file layout, camera and object poses, depth and normals pixel by pixel, ids, color per object.

    .venv/bin/python tools/compare_with_blenderproc.py basics/basic [ARGS...] [--keep DIR] [--markdown]

ARGS default to the example README's ``blenderproc run`` line; an argument containing ``output`` is each engine's
own output folder. Both engines run the unchanged script from the same extracted examples (tools/
blenderproc_reference.py; make its venv first with ``tools/blenderproc_reference.py setup``) through
tools/bproc_launch.py, with ``BLENDER_PROC_RANDOM_SEED=1`` and, on both, two additions: the label outputs the script
does not enable itself among depth, normals and instance segmentation by ``instance`` and ``name`` (the pixels, ids
and per-object regions compared; the layout row then lists these keys too), and both engines' view transform set to
``Standard`` (BlenderProc 2.8 defaults to Filmic, which tools/filmic_vs_blender.py compares on its own).

Rows (units: m, degrees, pixels):

- layout: every output file's name, and per HDF5 file its keys with dtype and shape; the differences listed;
- K / camera poses / object poses: the largest difference over the frames (objects matched by name);
- depth, normals: over pixels both engines see a surface and neither shows a silhouette edge
  (tools/bproc_metrics.py): median and 99th-percentile absolute difference, the fraction within 1 cm / 1 degree;
  normals once more without crease pixels (facet edges of flat-shaded meshes, where Cycles' antialiased pass
  blends two facets' normals and hybridgen samples the pixel centre);
- ``*_states`` (cam_states, light_states, object_states: JSON text): the largest difference of their numbers;
- ``<x>_segmaps``: the best one-to-one id mapping (hybridgen -> BlenderProc) and the pixels it makes agree, with
  edge pixels excluded; for instance ids, whether the mapping pairs objects of the same name;
- color per object: mean linear RGB of hybridgen and Cycles over the same (edge-free) pixels of each object, and
  the ratio of their luminances (hybridgen / Cycles).
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

TOOLS = Path(__file__).resolve().parent
sys.path.insert(0, str(TOOLS))

import bproc_metrics as metrics  # noqa: E402
from blenderproc_reference import (ReferenceUnavailable, example_args, examples_tree, execute,  # noqa: E402
                                   hybridgen_invocation, reference_invocation, script_path)
from bproc_outputs import (hdf5_frames, json_difference, layout, layout_differences,  # noqa: E402
                           names_by_instance)
from harness import Table  # noqa: E402

ENGINES = ("hybridgen", "blenderproc")
VERSION_KEYS = ("/blender_proc_version", "/hybridgen_version")
"""Each engine stores its own version under its own key: reported apart from the other layout differences."""
POSE_TOLERANCE = (1e-4, 0.01)
"""Poses within 0.1 mm and 0.01 degree are "equal" (Blender keeps matrices and Euler angles in float32)."""
SEED_ENV = {"BLENDER_PROC_RANDOM_SEED": "1"}


# --------------------------------------------------------------------------------------------- running
def kept_run(folder: Path, engine: str) -> dict[str, Any]:
    """A run whose output, scene dump and log are in ``folder`` (``--compare-only``, ``--reuse-blenderproc``)."""
    return {"output": folder / f"{engine}-output", "dump": folder / f"{engine}-scene.json", "status": 0,
            "log": folder / f"{engine}.log", "seconds": float("nan")}


def run_both(script: str, args: list[str] | None, folder: Path, timeout: float, tree: Path | None = None,
             engines: tuple[str, ...] = ENGINES) -> dict[str, dict[str, Any]]:
    """Each engine's run of ``script`` (``engines``; the others' runs are read from ``folder``):
    ``{engine: {"output", "dump", "status", "seconds", "log"}}``."""
    root = examples_tree()
    runs = {engine: kept_run(folder, engine) for engine in ENGINES}
    for engine in engines:
        output, dump, log = folder / f"{engine}-output", folder / f"{engine}-scene.json", folder / f"{engine}.log"
        shutil.rmtree(output, ignore_errors=True)
        output.mkdir(parents=True)
        engine_args = (example_args(script, root, output, folder / "inputs") if args is None
                       else [str(output) if "output" in arg else arg for arg in args])
        launch = ["--add-labels", "--view-transform", "Standard", "--scene-dump", str(dump)]
        if engine == "hybridgen":
            invocation = hybridgen_invocation(script, engine_args, launch, root, SEED_ENV, tree)
        else:
            invocation = reference_invocation(script, engine_args, launch, root, SEED_ENV)
        started = time.perf_counter()
        status = execute(invocation, log=log, timeout=timeout)
        runs[engine] = {"output": output, "dump": dump, "status": status, "log": log,
                        "seconds": time.perf_counter() - started}
    return runs


def last_line(log: Path) -> str:
    lines = [line for line in log.read_text(errors="replace").splitlines() if line.strip()]
    return lines[-1][:200] if lines else "(no output)"


# ------------------------------------------------------------------------------------------- comparing
def _poses_equal(differences: list[tuple[float, float]]) -> bool:
    return all(t < POSE_TOLERANCE[0] and r < POSE_TOLERANCE[1] for t, r in differences)


def _worst(differences: list[tuple[float, float]]) -> str:
    return (f"max {max((t for t, _ in differences), default=0):.2g} m, "
            f"{max((r for _, r in differences), default=0):.2g} deg")


def compare_scenes(ours: list[dict[str, Any]], theirs: list[dict[str, Any]]) -> list[tuple[str, str, str]]:
    """Rows for K, camera poses and object poses from the two scene dumps (one entry per render call)."""
    if len(ours) != len(theirs):
        return [("renders", "differ", f"hybridgen {len(ours)} render calls, BlenderProc {len(theirs)}")]
    k = max((float(np.max(np.abs(np.array(a["K"]) - np.array(b["K"])))) for a, b in zip(ours, theirs)), default=0.0)
    cams = [metrics.pose_difference(p, q) for a, b in zip(ours, theirs) for p, q in zip(a["cam2world"], b["cam2world"])]
    frames = sum(len(a["cam2world"]) for a in ours), sum(len(b["cam2world"]) for b in theirs)
    objects = [metrics.pose_difference(a["objects"][name], b["objects"][name])
               for a, b in zip(ours, theirs) for name in sorted(set(a["objects"]) & set(b["objects"]))]
    counts = len(ours[0]["objects"]) if ours else 0, len(theirs[0]["objects"]) if theirs else 0
    same_names = all(set(a["objects"]) == set(b["objects"]) for a, b in zip(ours, theirs))
    return [("K", "equal" if k < 1e-3 else "differ", f"max |dK| {k:.2g} px"),
            ("camera poses", "equal" if frames[0] == frames[1] and _poses_equal(cams) else "differ",
             f"{frames[0]} / {frames[1]} frames; {_worst(cams)}"),
            ("object poses", "equal" if same_names and _poses_equal(objects) else "differ",
             f"{counts[0]} / {counts[1]} objects{'' if same_names else ' (names differ)'}; {_worst(objects)}")]


def _agreement_row(name: str, values: metrics.Agreement, unit: str) -> tuple[str, str, str]:
    status = "within" if values.pixels and values.p99 <= values.tolerance else "differ" if values.pixels else "-"
    return (name, status, f"median {values.median:.3g} {unit}, p99 {values.p99:.3g} {unit}, "
                          f"{100 * values.within:.2f} % within {values.tolerance:g} {unit} "
                          f"({100 * values.coverage:.1f} % of pixels compared)")


def _id_row(key: str, match: metrics.IdMatch, names: tuple[dict[int, str], dict[int, str]]) -> tuple[str, str, str]:
    detail = f"{100 * match.agreement:.2f} % of pixels agree under " + ", ".join(
        f"{i}->{j}" for i, j in sorted(match.mapping.items()))
    if key == "instance_segmaps" and names[0] and names[1]:
        paired = [(i, j) for i, j in match.mapping.items() if i in names[0] and j in names[1]]
        detail += f"; same name {sum(names[0][i] == names[1][j] for i, j in paired)}/{len(paired)}"
    return key, "agree" if match.agreement > 0.999 else "differ", detail


COLOR_KEYS = ("colors", "diffuse")
"""uint8 sRGB images compared per object: the color and, where the script asks for it, the diffuse color."""


def color_per_object(pairs: list[tuple[dict[str, Any], dict[str, Any], np.ndarray]], mapping: dict[int, int],
                     names: dict[int, str], key: str = "colors") -> list[tuple[str, int, Any, Any, float]]:
    """Per instance (hybridgen's id, paired by ``mapping``): (name, pixels, hybridgen's and Cycles' mean linear RGB
    of ``key`` over the pixels both put on it within the frames' masks, luminance ratio)."""
    sums: dict[int, np.ndarray] = {}
    for a, b, mask in pairs:
        if key not in a or key not in b:
            continue
        linear_a, linear_b = metrics.srgb_to_linear(a[key]), metrics.srgb_to_linear(b[key])
        for i, j in mapping.items():
            region = mask & (a["instance_segmaps"] == i) & (b["instance_segmaps"] == j)
            if i and region.any():
                part = np.stack([linear_a[region].sum(0), linear_b[region].sum(0), np.full(3, region.sum())])
                sums[i] = sums.get(i, 0) + part
    rows = []
    for i, total in sorted(sums.items()):
        mean_a, mean_b = total[0] / total[2], total[1] / total[2]
        ratio = metrics.luminance(mean_a) / max(metrics.luminance(mean_b), 1e-9)
        rows.append((names.get(i, str(i)), int(total[2][0]), mean_a, mean_b, ratio))
    return rows


def compare_frames(ours: dict[str, dict[str, Any]], theirs: dict[str, dict[str, Any]]) -> tuple[list, dict]:
    """Rows for depth, normals, segmaps and states, and the per-object tables of COLOR_KEYS, of the HDF5 files both
    wrote."""
    pairs = []  # (ours, theirs, comparable mask) of every file both wrote with depth
    for name in sorted(set(ours) & set(theirs)):
        a, b = ours[name], theirs[name]
        if "depth" in a and "depth" in b:
            pairs.append((a, b, metrics.comparable(a["depth"], b["depth"], a.get("instance_segmaps"),
                                                   b.get("instance_segmaps"))))
    total = sum(mask.size for _, _, mask in pairs)
    rows = []
    if pairs:
        depth = np.concatenate([metrics.depth_differences(a["depth"], b["depth"], m) for a, b, m in pairs])
        rows.append(_agreement_row("depth", metrics.agreement(depth, 0.01, total), "m"))
    with_normals = [(a, b, m) for a, b, m in pairs if "normals" in a and "normals" in b]
    if with_normals:
        angles = np.concatenate([metrics.normal_differences(a["normals"], b["normals"], m)
                                 for a, b, m in with_normals])
        flat = np.concatenate([metrics.normal_differences(a["normals"], b["normals"],
                                                          m & ~metrics.crease_edges(a["normals"], b["normals"]))
                               for a, b, m in with_normals])
        rows.append(_agreement_row("normals", metrics.agreement(angles, 1.0, total), "deg"))
        rows.append(_agreement_row("normals, no crease", metrics.agreement(flat, 1.0, total), "deg"))
    names: tuple[dict[int, str], dict[int, str]] = ({}, {})
    for a, b, _ in pairs:
        names[0].update(names_by_instance(a.get("instance_attribute_maps")))
        names[1].update(names_by_instance(b.get("instance_attribute_maps")))
    matches = {}
    for key in sorted({k for a, b, _ in pairs for k in a if k.endswith("_segmaps") and k in b}):
        both = [(a[key][m], b[key][m]) for a, b, m in pairs if key in a and key in b]
        matches[key] = metrics.match_ids(np.concatenate([p for p, _ in both]), np.concatenate([q for _, q in both]))
        rows.append(_id_row(key, matches[key], names))
    for key in sorted({k for a, b, _ in pairs for k in a if k.endswith("_states") and k in b}):
        worst = max(json_difference(a[key], b[key]) for a, b, _ in pairs if key in a and key in b)
        rows.append((key, "equal" if worst < 1e-4 else "differ", f"max |difference| {worst:.2g} over its numbers"))
    colors = {key: color_per_object(pairs, matches["instance_segmaps"].mapping, names[0], key)
              for key in COLOR_KEYS if "instance_segmaps" in matches}
    return rows, {key: table for key, table in colors.items() if table}


def compare(runs: dict[str, dict[str, Any]]) -> tuple[list, dict]:
    """All rows of one example (see the module documentation)."""
    ours, theirs = runs["hybridgen"], runs["blenderproc"]
    failed = [(engine, run) for engine, run in runs.items() if run["status"] != 0]
    if failed:
        return [(f"{engine} run", f"fails ({run['status']})", last_line(run["log"])) for engine, run in failed], {}
    differences = layout_differences(layout(ours["output"]), layout(theirs["output"]))
    versions = [line for line in differences if line.split(":")[0].endswith(VERSION_KEYS)]
    others = [line for line in differences if line not in versions]
    files = len({line.split("/")[0] for line in versions})
    note = f"{'; ' if others else ''}* in {files} files hybridgen_version where BlenderProc writes blender_proc_version"
    rows = [("layout", ("equal" if not others else f"{len(others)} differ") + ("*" if versions else ""),
             "; ".join(others[:6]) + (" ..." if len(others) > 6 else "") + (note if versions else ""))]
    rows += compare_scenes(json.loads(ours["dump"].read_text()), json.loads(theirs["dump"].read_text()))
    frame_rows, color_tables = compare_frames(hdf5_frames(ours["output"]), hdf5_frames(theirs["output"]))
    return rows + frame_rows, color_tables


def print_report(example: str, runs: dict[str, dict[str, Any]], rows: list, color_tables: dict,
                 markdown: bool) -> None:
    seconds = ", ".join(f"{engine} {run['seconds']:.1f} s" for engine, run in runs.items())
    print(f"\n{example} ({seconds})")
    table = Table([("what", "<18"), ("result", "<10"), ("detail", "<")], markdown=markdown)
    table.header()
    for row in rows:
        table.row(*row)
    for key, color_rows in color_tables.items():
        print(f"\n{example}: {key} per object (mean linear RGB over the same edge-free pixels)")
        colors = Table([("object", "<22"), ("pixels", ">8d"), ("hybridgen RGB", "<22"), ("Cycles RGB", "<22"),
                        ("ratio Y", ">8.3f")], markdown=markdown)
        colors.header()
        for name, pixels, mean_a, mean_b, ratio in color_rows:
            colors.row(name, pixels, " ".join(f"{v:.3f}" for v in mean_a), " ".join(f"{v:.3f}" for v in mean_b),
                       ratio)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("example", help="basics/basic, examples/basics/basic or its main.py")
    parser.add_argument("args", nargs="*", help="the script's arguments (default: its README's; after -- when one "
                                                "starts with -)")
    parser.add_argument("--keep", type=Path, help="keep both engines' outputs and logs in this folder")
    parser.add_argument("--compare-only", action="store_true", help="compare the outputs already in --keep DIR")
    parser.add_argument("--reuse-blenderproc", action="store_true",
                        help="run hybridgen only, against BlenderProc's outputs already in --keep DIR (BlenderProc's "
                             "runs repeat exactly: fixed seeds)")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds per engine run (default 1800)")
    parser.add_argument("--markdown", action="store_true", help="Markdown tables")
    parser.add_argument("--hybridgen-tree", type=Path, help="run hybridgen from this source tree (e.g. a clone at "
                                                            "a commit; default: the installed checkout)")
    ns = parser.parse_args()
    if (ns.compare_only or ns.reuse_blenderproc) and ns.keep is None:
        parser.error("--compare-only and --reuse-blenderproc read the outputs in --keep DIR")
    script = script_path(ns.example)
    folder = ns.keep or Path(tempfile.mkdtemp(prefix="compare-bproc-"))
    try:
        engines = () if ns.compare_only else ("hybridgen",) if ns.reuse_blenderproc else ENGINES
        runs = run_both(script, ns.args or None, folder.resolve(), ns.timeout, ns.hybridgen_tree, engines)
        rows, color_tables = compare(runs)
    except ReferenceUnavailable as exc:
        raise SystemExit(str(exc)) from None
    finally:
        if ns.keep is None:
            shutil.rmtree(folder, ignore_errors=True)
    print_report(script.removeprefix("examples/").removesuffix("/main.py"), runs, rows, color_tables, ns.markdown)


if __name__ == "__main__":
    main()
