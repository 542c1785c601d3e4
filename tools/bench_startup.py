"""Time to first keypoint of a labels-only ``hybridgen run``, and the start-up cost of ``import hybridgen``.

Run: .venv/bin/python tools/bench_startup.py [--rounds 5] [--scenes monastery 1.4M] [--profile] [--importtime]
                                            [--baseline OTHER_CHECKOUT]
Needs pybullet (its ``pybullet_data`` meshes) and trimesh (the 1.4M scene is written once as a binary PLY).
``--baseline`` also times another checkout of hybridgen (e.g. ``git archive <commit> | tar -x -C /tmp/base``)
with the same interpreter, round by round alternating with this one, so that machine load hits both alike.

Every figure is a whole process, started by this script: wall seconds and CPU seconds (user + system of every
thread; ``wait4``), medians over ``--rounds``. CPU seconds are the steadier figure while other processes share
the cores. Rows:

- ``python -c 'import hybridgen'`` and ``hybridgen --help``;
- ``1st kp``: ``hybridgen run`` of a labels-only config (depth + normals + class + instance, default HDF5
  writer, 640x480, 1 keypoint) from process start to the first keypoint handed to the writer (the child
  stamps wall time and its own CPU time at that moment), plus the whole process. ``cold``: an empty cache
  folder (``HYBRIDGEN_CACHE_DIR``: mesh cache and input hashes); ``warm``: the caches of a previous run.

By default the children keep compiled bytecode in a private ``PYTHONPYCACHEPREFIX`` (warmed by an untimed run),
as an installed package has it; ``--no-bytecode`` measures with ``PYTHONDONTWRITEBYTECODE=1`` (every hybridgen
module compiled on each start). ``--profile`` prints a cProfile of one warm run; ``--importtime`` the slowest
imports of one warm run (``python -X importtime``).
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from harness import Table, alternating, load_average, medians, run_process
from label_configs import write_configs

TOOLS = Path(__file__).resolve().parent

SCENE_NAMES = {"monastery": "monastery (real)", "1.4M": "1.4M real, subdiv.", "50": "50 objects"}

FIRST_KEYPOINT_DRIVER = """\
import os, resource, sys, time
import hybridgen.io.hdf5_single as _single
_write = _single.Hdf5SingleFileWriter.write
def _stamped(self, index, values):
    if not getattr(_single, '_first_stamped', False):
        _single._first_stamped = True
        usage = resource.getrusage(resource.RUSAGE_SELF)
        with open(os.environ['BENCH_FIRST_KEYPOINT'], 'w') as out:
            out.write(repr((time.time(), usage.ru_utime + usage.ru_stime)))
    return _write(self, index, values)
_single.Hdf5SingleFileWriter.write = _stamped
from hybridgen.cli import main
sys.exit(main(sys.argv[1:]))
"""
"""The child of a ``1st kp`` row: the real CLI, with the writer's ``write`` wrapped to stamp its first call.
(It imports the HDF5 writer's module first, which a labels-only run with the default writer imports anyway.)"""


def timed(command: list[str], env: dict[str, str]) -> tuple[float, float, float]:
    """(start wall time.time(), wall seconds, CPU seconds of the whole process); fails loudly."""
    start_epoch = time.time()
    finished = run_process(command, env)
    return start_epoch, finished.wall, finished.cpu


def first_keypoint(config: Path, out: Path, env: dict[str, str], stamp: Path) -> dict[str, float]:
    """One labels-only run: seconds from process start to the first keypoint written (wall, CPU) and whole."""
    shutil.rmtree(out, ignore_errors=True)
    stamp.unlink(missing_ok=True)
    start, wall, cpu = timed([sys.executable, "-c", FIRST_KEYPOINT_DRIVER, "run", "-q", str(config), str(out)],
                             dict(env, BENCH_FIRST_KEYPOINT=str(stamp)))
    at, cpu_at = eval(stamp.read_text())  # noqa: S307 - our own repr of two floats
    return {"first_wall": at - start, "first_cpu": cpu_at, "wall": wall, "cpu": cpu}


def profile(command: list[str], env: dict[str, str], limit: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        stats = Path(tmp) / "run.prof"
        subprocess.run([sys.executable, "-m", "cProfile", "-o", str(stats), *command], env=env, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        import pstats

        pstats.Stats(str(stats)).sort_stats("cumulative").print_stats(limit)


def importtime(command: list[str], env: dict[str, str], limit: int) -> None:
    """The slowest imports (self time) and the top-level packages a run imports, by cumulative time."""
    done = subprocess.run([sys.executable, "-X", "importtime", *command], env=env, capture_output=True, text=True,
                          check=True)
    rows = []
    for line in done.stderr.splitlines():
        if line.startswith("import time:") and "|" in line and "self [us]" not in line:
            own, cumulative, name = line[len("import time:"):].split("|")
            rows.append((int(own), int(cumulative), name.rstrip()))
    top_level = sorted(((c, n.strip()) for _, c, n in rows if not n.startswith("  ")), reverse=True)
    print(f"imports of one warm run: {len(rows)} modules, {sum(r[0] for r in rows) / 1e3:.0f} ms in total; top level:")
    for cumulative, name in top_level[:limit]:
        print(f"  {cumulative / 1e3:7.1f} ms  {name}")
    print("largest self times:")
    for own, _, name in sorted(rows, reverse=True)[:limit]:
        print(f"  {own / 1e3:7.1f} ms  {name.strip()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5, help="runs per row (medians)")
    parser.add_argument("--scenes", nargs="+", default=["monastery", "1.4M"], choices=list(SCENE_NAMES))
    parser.add_argument("--baseline", type=Path, help="another hybridgen checkout to time alongside this one")
    parser.add_argument("--no-bytecode", action="store_true", help="children run with PYTHONDONTWRITEBYTECODE=1")
    parser.add_argument("--profile", action="store_true", help="cProfile of one warm run per scene")
    parser.add_argument("--importtime", action="store_true", help="python -X importtime of one warm run per scene")
    parser.add_argument("--limit", type=int, default=30, help="lines of --profile / --importtime")
    args = parser.parse_args()

    checkouts = {"this": TOOLS.parent} | ({"baseline": args.baseline.resolve()} if args.baseline else {})
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        base_env = dict(os.environ)
        if args.no_bytecode:
            base_env["PYTHONDONTWRITEBYTECODE"] = "1"
        else:
            base_env.pop("PYTHONDONTWRITEBYTECODE", None)
        envs = {}
        for name, root in checkouts.items():  # each its own caches and bytecode; the checkout first on sys.path
            envs[name] = dict(base_env, PYTHONPATH=str(root), HYBRIDGEN_CACHE_DIR=str(work / name / "cache"))
            if not args.no_bytecode:
                envs[name]["PYTHONPYCACHEPREFIX"] = str(work / name / "pycache")
            timed([sys.executable, "-m", "hybridgen", "--help"], envs[name])  # untimed: compiles bytecode
        os.chdir(work)  # not a checkout: '' on sys.path finds no hybridgen
        print(f"{os.cpu_count()} CPUs, load average {load_average():.1f} (others' processes skew wall times); "
              f"bytecode {'not cached' if args.no_bytecode else 'cached'}; medians of {args.rounds} whole processes, "
              f"checkouts alternating: " + ", ".join(f"{k} = {v}" for k, v in checkouts.items()))
        table = Table([("what", "<32"), ("checkout", "<9"), ("wall s", ">8.3f"), ("cpu s", ">8.3f")])
        table.header()
        for label, code in (("python -c 'import numpy'", ["-c", "import numpy"]),
                            ("python -c 'import hybridgen'", ["-c", "import hybridgen"]),
                            ("hybridgen --help", ["-m", "hybridgen", "--help"])):
            runs: dict[str, list[tuple[float, float]]] = {name: [] for name in checkouts}
            for r in range(args.rounds):
                for name in alternating(list(checkouts), r):
                    runs[name].append(timed([sys.executable, *code], envs[name])[1:])
            for name, values in runs.items():
                table.row(label, name, statistics.median(v[0] for v in values), statistics.median(v[1] for v in values))
        print(f"\nlabels-only run, 640x480, 1 keypoint: 1st kp = process start -> first keypoint handed to the "
              "writer; whole = the process; cold = empty cache folder (mesh cache, input hashes)")
        table = Table([("scene", "<10"), ("cache", "<6"), ("checkout", "<9"), ("1st kp wall s", ">13.3f"),
                       ("1st kp cpu s", ">12.3f"), ("whole wall s", ">12.3f"), ("whole cpu s", ">11.3f")])
        table.header()
        for short in args.scenes:
            config, _ = write_configs(SCENE_NAMES[short], "640x480", 1, work / "configs")
            out, stamp = work / "out", work / "stamp"
            rows: dict[tuple[str, str], list[dict[str, float]]] = {}
            for kind in ("cold", "warm"):
                for r in range(args.rounds):
                    for name in alternating(list(checkouts), r):
                        if kind == "cold":
                            shutil.rmtree(work / name / "cache", ignore_errors=True)
                        rows.setdefault((kind, name), []).append(first_keypoint(config, out, envs[name], stamp))
            for (kind, name), values in rows.items():
                m = medians(values)
                table.row(short, kind, name, m["first_wall"], m["first_cpu"], m["wall"], m["cpu"])
            command = ["-m", "hybridgen", "run", "-q", str(config), str(out)]
            for name in checkouts:
                if args.profile:
                    shutil.rmtree(out, ignore_errors=True)
                    print(f"\ncProfile of one warm run ({short}, {name}):")
                    profile(command, envs[name], args.limit)
                if args.importtime:
                    shutil.rmtree(out, ignore_errors=True)
                    print(f"\n{name}: ", end="")
                    importtime(command, envs[name], args.limit)
        print(f"\nload average at the end: {load_average():.1f}")


if __name__ == "__main__":
    main()
