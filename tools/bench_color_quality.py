"""Color quality: hybridgen's default color vs Blender Cycles at BlenderProc 2.8's defaults, each scored against
its own converged reference, on the four scenes of tools/color_quality.py.

Over 300 lines: the whole-process runs, their pairing with Cycles, the rows and the table of one benchmark; scenes,
references and Cycles are in color_quality.py, color_references.py and cycles_*.py.

Run: .venv/bin/python tools/bench_color_quality.py   (the issue's settings: 320x240, 4096-spp references)
     .venv/bin/python tools/bench_color_quality.py [--res 160x120] [--reference-spp 2048] [--scenes a,b]
     nice -n 10 .venv/bin/python tools/bench_color_quality.py --precompute cycles   (only fill the cache)
     (``tools/bench_color.py --quality [options]`` runs this with the same options)

For each scene: hybridgen's defaults (``PathTraceSettings()`` + denoising, as ``renderer.RgbRenderer``
with no color options: stratified samples, Blackman-Harris 1.5 px pixel filter, adaptive 64..768 spp at
noise threshold 0.005 in Cycles' meaning, indirect clamp 10, filter glossy 1.0, principled lobes sampled by
albedo, a constant world left to BSDF sampling, Cycles' roulette, 3 bounces for every lobe, OIDN; with
``--blenderproc-lobes`` glossy and transmission bounces 0 as Cycles renders at BlenderProc's defaults, with
``--lobes no-refractive-caustics`` ``caustics_refractive: false``),
timed as the issue asks: the WHOLE process (tools/default_color_process.py: Python's start, ``import
hybridgen``, the scene built from its mesh files, Mitsuba, kernels, raster guides, render, denoise, the PNG
written), wall clock from spawn to exit and CPU from the child's rusage. The first run of each scene gets
fresh Dr.Jit kernel and hybridgen mesh caches (a new user: reported as "cold"); the timed runs
(``--warm-runs``, median) reuse them, as a user's runs after the first. The in-process time of
``render_color`` is reported beside it. hybridgen's reference is the same estimator at a fixed
``--reference-spp`` without denoising (and once more without the clamp, to measure the clamp's bias).
Both engines use ``--threads`` CPU threads (2, the issue's). Cycles (pip ``bpy`` in ``.venv-bpy``) renders
with BlenderProc's defaults (``mode: blenderproc`` in tools/cycles_render.py), timed as its render only
(``bpy.ops.render.render``: Cycles' scene sync, BVH, render and denoise; building the Blender scene from the
export is not counted), and its reference at the same spp with ``mode: reference``. PSNR is computed on the
8-bit sRGB images (the ``colors`` users get). References come from the on-disk cache of
tools/reference_cache.py when their key matches (``--reference-cache PATH|off``; tools/color_references.py).
Side-by-side PNGs (hybridgen | its reference | Cycles | its reference) and the rows as JSON go to ``--out``.

The machine is shared: times are wall-clock under whatever load there is (the load average is printed at
start and end; CPU seconds are steadier). Cycles' timed render runs once beside each warm hybridgen run (after it
in even pairs, before it in odd ones: ABBA), and the table's ratios are the medians of the pairs' ratios, so a
drift in the machine's speed over minutes cancels.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np
from color_lobes import LOBES, lobes_name
from color_quality import SCENES
from color_references import CLAMP, References, scene_and_content
from cycles_worker import CyclesSession, ensure_bpy_venv
from harness import Table, alternating, host_cpu, paired_ratio, paired_ratios, run_process
from image_scores import psnr, read_png
from reference_cache import ReferenceCache, cache_root

REPO = Path(__file__).resolve().parents[1]


class DefaultRuns:
    """hybridgen's default render of one scene as whole processes (tools/default_color_process.py) that share
    fresh caches (Dr.Jit's kernels, hybridgen's parsed meshes): the first run is a new user's (cold), the
    next ones a returning user's (warm). Dr.Jit runs ``threads`` threads (``$HYBRIDGEN_THREADS``). Byte-compiled
    sources are used and written as by an installed package (``PYTHONDONTWRITEBYTECODE`` is dropped)."""

    def __init__(self, name: str, resolution: str, workdir: Path, lobes: str, threads: int) -> None:
        self.name, self.resolution, self.workdir, self.lobes = name, resolution, workdir, lobes
        self.caches = Path(tempfile.mkdtemp(prefix=f"{name}-caches-", dir=workdir))
        self.env = {**os.environ, "DRJIT_CACHE_DIR": str(self.caches / "drjit"),
                    "HYBRIDGEN_CACHE_DIR": str(self.caches / "hybridgen"), "HYBRIDGEN_THREADS": str(threads)}
        self.env.pop("PYTHONDONTWRITEBYTECODE", None)

    def run(self, png: Path, threshold: float | None = None, max_samples: int | None = None) -> dict[str, Any]:
        """One process (hybridgen's defaults but for a noise ``threshold`` and a ``max_samples`` when given):
        wall and CPU seconds, mean spp, and its phases (s): ``startup`` (spawn to the script's
        first line), ``import`` (hybridgen), ``build`` (the scene), ``render`` (render_color: scene translation,
        kernels, raster guides, render, denoise - the in-process time), ``write`` (the PNG), ``exit``."""
        command = [sys.executable, str(REPO / "tools" / "default_color_process.py"), self.name, self.resolution,
                   str(png), str(self.workdir), "--lobes", self.lobes]
        command += ["--threshold", str(threshold)] if threshold is not None else []
        command += ["--max-samples", str(max_samples)] if max_samples is not None else []
        spawned = time.time()
        finished = run_process(command, self.env)
        r = finished.report
        assert r is not None, f"{command[1]} printed no report"
        return {"wall": finished.wall, "cpu": finished.cpu, "mean_spp": r["mean_spp"],
                "startup": r["started"] - spawned, "import": r["imported"] - r["started"],
                "build": r["built"] - r["imported"], "render": r["rendered"] - r["built"],
                "write": r["written"] - r["rendered"], "exit": finished.wall - (r["written"] - spawned)}

    def close(self) -> None:
        shutil.rmtree(self.caches, ignore_errors=True)


PHASES = ("startup", "import", "build", "render", "write", "exit")
"""The phases of a timed hybridgen process (:meth:`DefaultRuns.run`)."""


def time_hybridgen(name: str, resolution: str, workdir: Path, args: Any, reference: np.ndarray,
                   row: dict[str, Any], partner: Callable[[], None] | None = None) -> np.ndarray:
    """Fills ``row`` with hybridgen's whole-process numbers (one cold run, ``args.warm_runs`` warm ones:
    medians, and each warm run's times) and PSNR; returns its frame. ``partner`` (Cycles' timed render) runs once
    beside each warm run - after it in even pairs, before it in odd ones - so each pair of timings sees the same
    state of the shared machine and a drift in its speed cancels in the pair's ratio."""
    runs = DefaultRuns(name, resolution, workdir, lobes_name(args), args.threads)
    try:
        cold_png, png = workdir / f"{name}_hybridgen_cold.png", workdir / f"{name}_hybridgen.png"
        cold = runs.run(cold_png, args.hg_threshold, args.hg_max_samples)
        warm = []
        for pair in range(max(1, args.warm_runs)):
            for engine in alternating(["hybridgen", "cycles"] if partner is not None else ["hybridgen"], pair):
                if engine == "hybridgen":
                    warm.append(runs.run(png, args.hg_threshold, args.hg_max_samples))
                else:
                    partner()  # type: ignore[misc]
        for threshold in args.try_thresholds:  # tuning: other thresholds, same reference, warm
            other_png = workdir / f"{name}_hybridgen_{threshold}.png"
            other = runs.run(other_png, threshold, args.hg_max_samples)
            row[f"hg_{threshold}"] = {"psnr": psnr(read_png(other_png), reference), "s": other["wall"],
                                      "spp": other["mean_spp"], "cpu_s": other["cpu"]}
    finally:
        runs.close()
    image = read_png(png)
    typical = sorted(warm, key=lambda run: run["wall"])[(len(warm) - 1) // 2]
    row.update(hg_psnr=psnr(image, reference), hg_mean_spp=typical["mean_spp"],
               hg_s=statistics.median(run["wall"] for run in warm),
               hg_cpu_s=statistics.median(run["cpu"] for run in warm), hg_cold_s=cold["wall"],
               hg_cold_cpu_s=cold["cpu"], hg_inprocess_s=typical["render"],
               hg_warm_s=[run["wall"] for run in warm], hg_warm_cpu_s=[run["cpu"] for run in warm],
               hg_phases={key: round(typical[key], 3) for key in PHASES},
               hg_cold_phases={key: round(cold[key], 3) for key in PHASES},
               hg_same_bytes_cold_warm=bool(np.array_equal(read_png(cold_png), image)))
    return image


class CyclesTimes:
    """Cycles' timed renders at BlenderProc's defaults (``bpy.ops.render.render`` alone), one per call, each
    into the same PNG (the same seed: the same frame)."""

    def __init__(self, name: str, session: CyclesSession, workdir: Path) -> None:
        self.name, self.session, self.png = name, session, workdir / f"{name}_cycles.png"
        self.answers: list[dict[str, Any]] = []

    def __call__(self) -> None:
        self.answers.append(self.session.render(1, self.png, mode="blenderproc"))

    def finish(self, workdir: Path, row: dict[str, Any]) -> np.ndarray:
        """After :func:`time_hybridgen` ran one render per warm run: fills ``row`` with the renders' median times,
        each render's times and the per-pair ratios to hybridgen's warm runs (``row['hg_warm_s']``, in the same
        order) with their medians, which the table reports; returns Cycles' frame."""
        walls, cpus = [a["seconds"] for a in self.answers], [a["cpu_s"] for a in self.answers]
        row.update(cycles_s=statistics.median(walls), cycles_cpu_s=statistics.median(cpus), cycles_runs_s=walls,
                   cycles_runs_cpu_s=cpus, pair_wall_ratios=paired_ratios(row["hg_warm_s"], walls),
                   pair_cpu_ratios=paired_ratios(row["hg_warm_cpu_s"], cpus),
                   wall_ratio=paired_ratio(row["hg_warm_s"], walls), cpu_ratio=paired_ratio(row["hg_warm_cpu_s"], cpus))
        # Its samples per pixel from the same render again with Cycles' Debug Sample Count pass (untimed: the pass
        # is not part of BlenderProc's defaults), so the two engines' samples can be compared, not only their times.
        counts = workdir / f"{self.name}_cycles_counts.npy"
        self.session.render(1, workdir / f"{self.name}_cycles_counted.png", mode="blenderproc",
                            sample_counts=str(counts))
        row["cycles_mean_spp"] = float(np.load(counts).mean())
        return read_png(self.png)


def quality_row(name: str, scene: Any, content: str, refs: References, session: CyclesSession | None,
                args: Any, workdir: Path, out: Path) -> dict[str, Any]:
    """One scene's row: both engines' defaults timed in interleaved pairs (:func:`time_hybridgen`) and scored
    against their references; the side-by-side PNG (hybridgen | its reference | Cycles | its reference)."""
    from PIL import Image

    resolution = refs.resolution
    row: dict[str, Any] = {"scene": name, "resolution": resolution, "reference_spp": refs.spp, "lobes": refs.lobes,
                           "hg_threshold": args.hg_threshold, "hg_max_samples": args.hg_max_samples,
                           "cpu": host_cpu()}
    ref, record = refs.hybridgen(name, scene, content, CLAMP)
    ref_unclamped, _ = refs.hybridgen(name, scene, content, 0.0)
    row["hg_ref_s"], row["hg_ref_cached"] = record["seconds"], record["cached"]
    cycles_times = CyclesTimes(name, session, workdir) if session is not None else None
    image = time_hybridgen(name, resolution, workdir, args, ref, row, cycles_times)
    row["hg_psnr_vs_unclamped_ref"] = psnr(image, ref_unclamped)
    row["clamp_bias_psnr"] = psnr(ref, ref_unclamped)
    row["clamp_bias_mean"] = float(ref.astype(float).mean() - ref_unclamped.astype(float).mean())
    panels = [image, ref]
    if cycles_times is not None:
        cycles = cycles_times.finish(workdir, row)
        cycles_ref, record = refs.cycles(name, content, cycles_times.session)
        row["cycles_psnr"] = psnr(cycles, cycles_ref)
        row["cycles_ref_s"], row["cycles_ref_cached"] = record["seconds"], record["cached"]
        panels += [cycles, cycles_ref]
    Image.fromarray(np.concatenate(panels, axis=1)).save(out / f"{name}_side_by_side.png")
    return row


def precompute(name: str, scene: Any, content: str, refs: References, session: CyclesSession | None,
               engines: str) -> None:
    """Renders (or finds) the references of ``engines`` ("cycles", "hybridgen" or "all") and says which."""
    found: list[tuple[str, dict[str, Any]]] = []
    if engines in ("hybridgen", "all"):
        found += [(f"hybridgen clamp {clamp:g}", refs.hybridgen(name, scene, content, clamp)[1])
                  for clamp in (CLAMP, 0.0)]
    if engines in ("cycles", "all") and session is not None:
        found.append(("Cycles", refs.cycles(name, content, session)[1]))
    for what, record in found:
        state = "cached" if record["cached"] else f"rendered in {record['seconds']:.1f} s"
        print(f"{name} {refs.resolution} {refs.spp} spp, {what}: {state}", flush=True)


def run_quality(args: Any, bpy_python: Path | None) -> list[dict[str, Any]]:
    """The quality benchmark (or, with ``args.precompute``, only its references): one row per scene."""
    width, height = (int(v) for v in args.res.lower().split("x"))
    resolution = f"{width}x{height}"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    workdir = Path(tempfile.mkdtemp(prefix="bench_color_quality_"))  # private: concurrent runs share --out
    cache = ReferenceCache(cache_root(args.reference_cache))
    refs = References(cache, args.reference_spp, resolution, lobes_name(args), bpy_python,
                      workdir)
    load = os.getloadavg()
    print(f"{resolution}, references {args.reference_spp} spp, {args.threads} threads per engine, reference cache "
          f"{cache.root if cache.root else 'off'}; {os.cpu_count()} cores, load average {load[0]:.2f} "
          f"{load[1]:.2f} {load[2]:.2f} at start", flush=True)
    cpu = host_cpu()
    print(f"CPU: {cpu['model']}, {cpu['isa']} (Dr.Jit LLVM {cpu['drjit_llvm_lanes']} lanes)", flush=True)
    rows = []
    try:
        for name in args.scenes.split(",") if args.scenes else SCENES:
            scene, npz, content = scene_and_content(name, width, height, workdir, threads=args.threads)
            session = CyclesSession(bpy_python, npz) if bpy_python is not None else None
            try:
                if args.precompute:
                    precompute(name, scene, content, refs, session, args.precompute)
                    continue
                row = quality_row(name, scene, content, refs, session, args, workdir, out)
            finally:
                if session is not None:
                    session.close()
            rows.append(row)
            print(json.dumps(row), flush=True)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} at the end", flush=True)
    if rows:
        (out / f"quality_{resolution}_{args.reference_spp}spp.json").write_text(json.dumps(rows, indent=1))
    return rows


def _row_name(row: dict[str, Any]) -> str:
    """The scene's name in the table, with hybridgen's settings where they are not its defaults (rows of older
    JSON files have no such keys)."""
    notes = [f"{row['lobes']} lobes"] if row.get("lobes", "default") != "default" else []
    notes += [f"threshold {row['hg_threshold']:g}"] if row.get("hg_threshold") is not None else []
    notes += [f"at most {row['hg_max_samples']} spp"] if row.get("hg_max_samples") is not None else []
    return row["scene"] + (f" ({', '.join(notes)})" if notes else "")


def print_table(rows: list[dict[str, Any]], reference_spp: int) -> None:
    """The rows as a Markdown table (goal: hybridgen's PSNR >= Cycles' and time ratio <= 0.5)."""
    if not rows:
        return
    nan = float("nan")
    print(f"\nPSNR (dB, 8-bit sRGB) against each engine's own {reference_spp}-spp reference at "
          f"{rows[0]['resolution']}. hybridgen: the whole process (median of warm runs; cold = fresh Dr.Jit kernel "
          "and mesh caches; in-proc = render_color alone); Cycles: its render only, at BlenderProc's defaults "
          "(median of as many renders, each paired with a warm run). CPU = user + system s of every thread. Ratio = "
          "hybridgen / Cycles, the median of the pairs' ratios.\n")
    table = Table([("scene", ""), ("hybridgen dB (mean spp)", ""), ("hg wall s", ".2f"), ("hg CPU s", ".2f"),
                   ("hg cold wall s", ".2f"), ("hg in-proc s", ".2f"), ("Cycles dB (mean spp)", ""),
                   ("Cycles wall s", ".2f"), ("Cycles CPU s", ".2f"), ("wall ratio", ".2f"), ("CPU ratio", ".2f"),
                   ("goal (wall / CPU)", ""), ("clamp bias dB", ".1f")], markdown=True)
    table.header()
    for r in rows:
        # the median of the interleaved pairs' ratios; rows of older JSON files: the ratio of the medians
        wall_ratio = r.get("wall_ratio", r["hg_s"] / r["cycles_s"] if r.get("cycles_s") else nan)
        cpu_ratio = r.get("cpu_ratio", r["hg_cpu_s"] / r["cycles_cpu_s"] if r.get("cycles_cpu_s") else nan)
        clean = r["hg_psnr"] >= r.get("cycles_psnr", nan)
        goal = " / ".join("yes" if clean and ratio <= 0.5 else "no" for ratio in (wall_ratio, cpu_ratio))
        table.row(_row_name(r), f"{r['hg_psnr']:.1f} ({r['hg_mean_spp']:.0f})", r["hg_s"], r["hg_cpu_s"],
                  r["hg_cold_s"], r["hg_inprocess_s"],
                  f"{r.get('cycles_psnr', nan):.1f} ({r.get('cycles_mean_spp', nan):.0f})", r.get("cycles_s", nan),
                  r.get("cycles_cpu_s", nan), wall_ratio, cpu_ratio, goal, r["clamp_bias_psnr"])
    print("\nclamp bias: PSNR of hybridgen's clamped reference against its unclamped one (higher = less bias; inf = "
          "none). Warm-run phases (s) per scene, startup / import / build / render / write / exit:")
    for r in rows:
        print(f"  {r['scene']}: " + " / ".join(f"{r['hg_phases'][k]:.2f}" for k in PHASES)
              + " (cold: " + " / ".join(f"{r['hg_cold_phases'][k]:.2f}" for k in PHASES) + ")")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--res", default="320x240", help="WxH (default 320x240)")
    parser.add_argument("--no-cycles", action="store_true", help="skip Blender Cycles")
    parser.add_argument("--bpy-venv", type=Path, default=REPO / ".venv-bpy")
    parser.add_argument("--reference-spp", type=int, default=4096, help="reference spp")
    parser.add_argument("--hg-threshold", type=float, default=None, help="hybridgen's noise threshold (default: its "
                        "default)")
    parser.add_argument("--hg-max-samples", type=int, default=None, help="hybridgen's maximum samples per pixel, "
                        "adaptive at its threshold (default: its default)")
    parser.add_argument("--try-thresholds", type=lambda v: [float(x) for x in v.split(",")], default=[],
                        help="also time hybridgen at these noise thresholds (tuning)")
    parser.add_argument("--blenderproc-lobes", action="store_true", help="hybridgen with BlenderProc's "
                        "glossy_bounces 0 / transmission_bounces 0, the light paths Cycles renders")
    parser.add_argument("--lobes", choices=sorted(LOBES), default=None, help="hybridgen's light paths "
                        "(tools/color_lobes.py; --blenderproc-lobes is --lobes blenderproc)")
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default all)")
    parser.add_argument("--out", default=str(REPO / "output" / "bench_color_quality"),
                        help="folder for side-by-side PNGs and the rows (JSON)")
    parser.add_argument("--threads", type=int, default=2, help="CPU threads of both engines (hybridgen: "
                        "$HYBRIDGEN_THREADS; default 2, the issue's)")
    parser.add_argument("--warm-runs", type=int, default=1, help="timed (warm-cache) hybridgen processes per "
                        "scene, median (after one cold run)")
    parser.add_argument("--reference-cache", default=None, help="folder of the reference cache (default "
                        "$HYBRIDGEN_BENCH_CACHE or ~/.cache/hybridgen/bench_color; 'off': none)")
    parser.add_argument("--precompute", choices=("cycles", "hybridgen", "all"), default=None,
                        help="only render the missing references of these engines into the cache")
    args = parser.parse_args()
    python = None if args.no_cycles else ensure_bpy_venv(args.bpy_venv)
    print_table(run_quality(args, python), args.reference_spp)


if __name__ == "__main__":
    main()
