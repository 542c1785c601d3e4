"""hybridgen vs the real BlenderProc on the same BlenderProc 2 example script on this machine: whole-process wall
time of each (alternating runs, medians, the paired ratio) and the PSNR of each engine's default colors against
its OWN converged reference.

    .venv/bin/python tools/bench_blenderproc.py basics/basic [--rounds 2] [--reference-spp 1024] [--markdown]

Timed runs are the plain user commands, from the extracted examples (tools/blenderproc_reference.py; make its venv
with ``tools/blenderproc_reference.py setup``): ``hybridgen run examples/.../main.py ARGS`` and BlenderProc's
``python examples/.../main.py ARGS`` (USE_EXTERNAL_BPY_MODULE), with the README's arguments, each into a fresh
output folder, ``BLENDER_PROC_RANDOM_SEED=1``, in ABBA order (tools/harness.py), after both engines' Python sources
are compiled to bytecode (as a pip install does; see :func:`compile_bytecode`). Wall seconds are spawn to exit;
CPU seconds are the process's user + system.

Quality: frame 0's ``colors`` (uint8, what users get: BlenderProc's default Filmic view in both engines - hybridgen's
from Blender's tables, found here in ``.venv-blenderproc``; Standard where none are installed) of the
first timed run against that engine's reference: the same script rendered by the same engine through
tools/bproc_launch.py with ``--samples N --noise-threshold 0 --no-denoiser --frames 1`` (fixed N spp, no adaptive
stop, no denoiser; the first frame only). References are cached under ``$HYBRIDGEN_BLENDERPROC_CACHE/references``
(default ``~/.cache/hybridgen/blenderproc/references``) by engine, script content, arguments, spp and the engine's
version (BlenderProc: its source commit; hybridgen: the git commit of its tree plus a digest of its uncommitted
changes under hybridgen/); ``--reference-cache off`` renders them again. ``--hybridgen-tree DIR`` runs hybridgen from
another source tree (e.g. ``git clone --shared . /tmp/hg`` at a commit, put first on PYTHONPATH): a shared working
tree that others are editing can be half-way through a change.

``--profile`` adds one hybridgen run through tools/bproc_launch.py ``--profile`` (not timed against BlenderProc) and
prints where its time goes: start-up (interpreter and exit: the whole process minus what ran in it), imports,
scene load, Mitsuba scene build, kernel compilation, sampling, labels, denoising guides, waiting for the denoiser,
writing - the render loop's thread, adding up to the whole process - and, beside them, what other threads do: Open
Image Denoise (it overlaps the next frame's sampling), the guide worker's draws and the guides' filtering.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

TOOLS = Path(__file__).resolve().parent
sys.path.insert(0, str(TOOLS))

from blenderproc_reference import (CACHE, REPO, Invocation, ReferenceUnavailable, check_ready,  # noqa: E402
                                   commit_of, example_args, examples_tree, hybridgen_invocation, key_of,
                                   reference_invocation, script_path, source_tree)
from bproc_outputs import hdf5_frames  # noqa: E402
from harness import Table, alternating, load_average, paired_ratio, run_process  # noqa: E402
from image_scores import db, mse  # noqa: E402

ENGINES = ("hybridgen", "blenderproc")
SEED_ENV = {"BLENDER_PROC_RANDOM_SEED": "1"}
GOAL = 5.0
"""The issue's goal: hybridgen's whole process at least this many times faster, at equal or better PSNR."""
STAGES = ("imports", "scene_load", "mitsuba_scene", "kernel_compile", "sampling", "labels", "denoise_guides",
          "denoise_wait", "write")
"""The stages of the render loop's thread, in order (``denoise`` runs on a thread of its own beside them)."""


BLENDERPROC_DONE = "Cleaning temporary directory"
"""BlenderProc's last line once a script's files are written (a crash after it is counted as finished)."""
HYBRIDGEN_TREE: list[Path | None] = [None]
"""``--hybridgen-tree``: the hybridgen source tree the runs use (None: the installed checkout)."""


def invocation(engine: str, script: str, args: list[str], launch: list[str] | None = None) -> Invocation:
    if engine == "hybridgen":
        return hybridgen_invocation(script, args, launch, extra_env=SEED_ENV, tree=HYBRIDGEN_TREE[0])
    return reference_invocation(script, args, launch, extra_env=SEED_ENV)


def timed(engine: str, script: str, work: Path, label: str, launch: list[str] | None = None) -> tuple[Any, Path]:
    """One whole-process run into ``work/<label>``: (harness.Finished, its output folder)."""
    output = work / label
    args = example_args(script, examples_tree(), output, work / "inputs")
    run = invocation(engine, script, args, launch)
    # bpy 4.2 may segfault on its way out after BlenderProc has written everything (basics/material_manipulation)
    crash_after = BLENDERPROC_DONE if engine == "blenderproc" else None
    return run_process(run.command, env=run.env, cwd=run.cwd, crash_after=crash_after), output


def compile_bytecode() -> None:
    """Writes the bytecode of both engines' Python sources before the timed runs, as a regular ``pip install`` does.
    hybridgen (installed editable) and BlenderProc (its source folder on PYTHONPATH) are plain source trees here, and
    this machine sets PYTHONDONTWRITEBYTECODE, so without this every process compiles each module it imports
    (hybridgen ~120 modules, ~0.1 s a run)."""
    trees = [(Path(sys.executable), (HYBRIDGEN_TREE[0] or REPO) / "hybridgen"),
             (check_ready(), source_tree() / "blenderproc")]
    for python, tree in trees:
        subprocess.run([str(python), "-m", "compileall", "-q", str(tree)], stdout=subprocess.DEVNULL, check=True)


def first_colors(output: Path) -> np.ndarray:
    """``colors`` of the first HDF5 file (by number) the script wrote."""
    frames = hdf5_frames(output)
    first = min(frames, key=lambda name: (len(name), name))
    return np.asarray(frames[first]["colors"])


# ------------------------------------------------------------------------------------------ references
def engine_version(engine: str) -> str:
    """What the engine's reference depends on besides the script: BlenderProc's source commit and bpy; hybridgen's
    tree's commit plus a digest of its uncommitted changes to hybridgen/."""
    if engine == "blenderproc":
        return f"blenderproc {commit_of('HEAD')} bpy 4.2.0"
    tree = str(HYBRIDGEN_TREE[0] or REPO)
    head = subprocess.run(["git", "-C", tree, "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    diff = subprocess.run(["git", "-C", tree, "diff", "HEAD", "--", "hybridgen"], capture_output=True).stdout
    return f"hybridgen {head.strip()} {key_of(diff.decode(errors='replace'))}"


def reference(engine: str, script: str, spp: int, work: Path, cache: Path | None,
              seed: int = 0) -> tuple[np.ndarray, str]:
    """The engine's converged frame 0 (uint8 sRGB) rendered with path-tracer seed ``seed`` (0: the engine's
    default) and where it came from (cached or rendered, seconds)."""
    root = examples_tree()
    readme = json.dumps(example_args(script, root, work / "OUTPUT", work / "inputs")).replace(str(work), "")
    key = key_of(engine, (root / script).read_text(), readme, str(spp), engine_version(engine),
                 *([f"seed {seed}"] if seed else []))
    entry = cache / f"{engine}-{Path(script).parent.name}-{spp}spp-{key}.npy" if cache else None
    if entry is not None and entry.is_file():
        return np.load(entry), "cached"
    launch = ["--samples", str(spp), "--noise-threshold", "0", "--no-denoiser", "--frames", "1", "--seed", str(seed)]
    finished, output = timed(engine, script, work, f"{engine}-reference-{seed}", launch)
    image = first_colors(output)
    if entry is not None:
        entry.parent.mkdir(parents=True, exist_ok=True)
        partial = entry.with_suffix(".partial.npy")
        np.save(partial, image)
        partial.rename(entry)
    return image, f"rendered in {finished.wall:.0f} s"


@dataclass(frozen=True)
class Score:
    """Frame 0's PSNR against an engine's references (uint8 sRGB, each ``--reference-spp`` with its own seed).

    ``raw``: against the first reference (seed 0), as the benchmark scored before. A reference of N spp without
    a denoiser has noise of its own, and the squared error against it adds the reference's variance to the
    frame's: ``E|x - r|^2 = E|x - t|^2 + E|r - t|^2`` for a frame x independent of the reference r (t: the
    converged value). Two references of independent seeds estimate that variance as half their mean squared
    difference, so ``truth`` is the PSNR of ``mean_i MSE(x, r_i) - mean_(i<j) MSE(r_i, r_j) / 2``: the frame's
    error against the converged image, with the references' noise taken out (``references``: the PSNR between
    the references themselves)."""

    raw: float
    mse_each: tuple[float, ...]
    reference_mse: float | None

    @staticmethod
    def of(image: np.ndarray, references: list[np.ndarray]) -> "Score":
        each = tuple(mse(image, ref) for ref in references)
        pairs = [mse(a, b) for i, a in enumerate(references) for b in references[i + 1:]]
        return Score(db(each[0]), each, float(np.mean(pairs)) if pairs else None)

    @property
    def truth(self) -> float:
        if self.reference_mse is None:
            return float("nan")
        return db(max(float(np.mean(self.mse_each)) - self.reference_mse / 2, 1e-12))

    @property
    def references(self) -> float:
        return float("nan") if self.reference_mse is None else db(self.reference_mse)

    @property
    def verdict(self) -> float:
        """The score the goal is judged on: ``truth`` where there are two or more references, else ``raw``."""
        return self.raw if self.reference_mse is None else self.truth

    @property
    def verdict_kind(self) -> str:
        return "against one reference" if self.reference_mse is None else "against the converged image"


# ----------------------------------------------------------------------------------------------- profile
def profile(script: str, work: Path) -> dict[str, float]:
    """One hybridgen run through tools/bproc_launch.py --profile: seconds per stage (see the module doc)."""
    path = work / "profile.json"
    finished, _ = timed("hybridgen", script, work, "hybridgen-profile", ["--profile", str(path)])
    spent = json.loads(path.read_text())
    spent["startup_and_exit"] = finished.wall - spent["in_process"]
    spent["whole_process"] = finished.wall
    return spent


def print_profile(spent: dict[str, float], markdown: bool) -> None:
    sampling = spent.get("sampling", 0.0) - spent.get("kernel_compile", 0.0)
    rows = [("start-up and exit (interpreter)", spent["startup_and_exit"])]
    rows += [(stage, spent.get(stage, 0.0)) for stage in STAGES if stage != "sampling"]
    rows.insert(5, ("sampling (kernel compile excluded)", sampling))
    # kernel_compile is part of sampling
    inside = spent.get("render", 0.0) - sum(spent.get(s, 0.0) for s in STAGES[2:8] if s != "kernel_compile")
    rows.append(("render() other (scene conversion, tonemap, segmaps)", inside))
    rows.append(("script's own and other", spent["in_process"] - spent.get("imports", 0.0)
                 - spent.get("scene_load", 0.0) - spent.get("render", 0.0) - spent.get("write", 0.0)))
    table = Table([("hybridgen stage", "<52"), ("s", ">8.2f"), ("share", ">7.1%")], markdown=markdown)
    table.header()
    for name, seconds in rows:
        table.row(name, seconds, seconds / spent["whole_process"])
    table.row("whole process", spent["whole_process"], 1.0)
    table.row("denoise, guides drawn and filtered (other threads, beside)", spent.get("denoise", 0.0),
              spent.get("denoise", 0.0) / spent["whole_process"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("example", help="basics/basic, examples/basics/basic or its main.py")
    parser.add_argument("--rounds", type=int, default=2, help="timed runs per engine, ABBA (default 2)")
    parser.add_argument("--reference-spp", type=int, default=1024, help="the references' fixed spp (default 1024)")
    parser.add_argument("--reference-seeds", type=int, default=2,
                        help="references per engine, each with its own path-tracer seed (default 2; 1: the raw "
                             "score only)")
    parser.add_argument("--reference-cache", default=None, help="a folder, or 'off' (default: under the cache)")
    parser.add_argument("--profile", action="store_true", help="add one profiled hybridgen run")
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--hybridgen-tree", type=Path, help="run hybridgen from this source tree (e.g. a clone at "
                                                            "a commit; default: the installed checkout)")
    ns = parser.parse_args()
    HYBRIDGEN_TREE[0] = ns.hybridgen_tree.resolve() if ns.hybridgen_tree else None
    script = script_path(ns.example)
    cache = (None if ns.reference_cache == "off" else
             Path(ns.reference_cache) if ns.reference_cache else CACHE / "references")
    walls: dict[str, list[float]] = {engine: [] for engine in ENGINES}
    cpus: dict[str, list[float]] = {engine: [] for engine in ENGINES}
    firsts: dict[str, Path] = {}
    try:
        with tempfile.TemporaryDirectory(prefix="bench-bproc-") as temp:
            work = Path(temp)
            compile_bytecode()
            print(f"{script}: {ns.rounds} rounds, load average {load_average():.1f} at start", flush=True)
            for round_index in range(ns.rounds):
                for engine in alternating(ENGINES, round_index):
                    finished, output = timed(engine, script, work, f"{engine}-{round_index}")
                    walls[engine].append(finished.wall)
                    cpus[engine].append(finished.cpu)
                    firsts.setdefault(engine, output)
                    print(f"  round {round_index} {engine:12s} {finished.wall:7.1f} s wall {finished.cpu:7.1f} s CPU",
                          flush=True)
            scores, sources = {}, {}
            for engine in ENGINES:
                images = []
                for seed in range(max(1, ns.reference_seeds)):
                    image, source = reference(engine, script, ns.reference_spp, work, cache, seed)
                    images.append(image)
                    sources.setdefault(engine, source)
                scores[engine] = Score.of(first_colors(firsts[engine]), images)
            spent = profile(script, work) if ns.profile else None
    except ReferenceUnavailable as exc:
        raise SystemExit(str(exc)) from None
    import statistics

    table = Table([("engine", "<12"), ("median wall s", ">14.1f"), ("median CPU s", ">13.1f"), ("PSNR dB", ">8.2f"),
                   ("PSNR truth dB", ">14.2f"), ("references agree dB", ">20.2f"), ("reference", "<30")],
                  markdown=ns.markdown)
    print(f"\n{script} (load average {load_average():.1f} at end)")
    table.header()
    for engine in ENGINES:
        score = scores[engine]
        table.row(engine, statistics.median(walls[engine]), statistics.median(cpus[engine]), score.raw,
                  score.truth, score.references, f"{len(score.mse_each)} x {ns.reference_spp} spp, {sources[engine]}")
    speed = 1.0 / paired_ratio(walls["hybridgen"], walls["blenderproc"])
    cpu_speed = 1.0 / paired_ratio(cpus["hybridgen"], cpus["blenderproc"])
    ours, theirs = scores["hybridgen"].verdict, scores["blenderproc"].verdict
    verdict = "meets" if speed >= GOAL and ours >= theirs else "misses"
    print(f"hybridgen {speed:.2f}x faster (whole process, wall; CPU {cpu_speed:.2f}x) at PSNR "
          f"{ours:.2f} dB vs BlenderProc {theirs:.2f} dB ({scores['hybridgen'].verdict_kind}): {verdict} the goal "
          f"(>= {GOAL:g}x at equal or better PSNR)")
    if spent is not None:
        print()
        print_profile(spent, ns.markdown)


if __name__ == "__main__":
    main()
