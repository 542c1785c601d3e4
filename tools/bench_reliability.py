"""What reliability costs: fingerprints and checksums on a 400-keypoint labels run, and peak memory of a
labels-only run over 12 vs 120 scenes (memory must not grow with the number of scenes).

Run: .venv/bin/python tools/bench_reliability.py [--keypoints 400] [--scenes 12 120] [--rounds 3]

Overhead: the run is timed end to end (``hybridgen run`` in a fresh process), and the three added steps
are timed on its outputs in this process: computing the fingerprint (config leaves + input file hashes,
once per run), sealing (the SHA-256 over stored chunks written before commit, once per file) and
verifying (what a resume does per existing file). Peak RSS is ``ru_maxrss`` of the run's process.
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))
from bench_workers import CONFIG, KINDS  # noqa: E402  (one scene template for the run benchmarks)


def config_text(scenes: int, width: int, height: int, keypoints: int) -> str:
    """bench_workers.py's labels-only scene (knot over a floor, sampled cameras, depth/distance/normals/ids)."""
    labels = KINDS["labels"]
    return CONFIG.format(scenes=scenes, repo=REPO, width=width, height=height, keypoints=keypoints,
                         renderer=labels["renderer"], renderer_config=labels["renderer_config"])


def _run(config: Path, out: Path) -> tuple[float, int]:
    """(seconds, peak RSS in MiB) of one ``hybridgen run`` in a fresh process."""
    code = ("import resource, sys, time; from hybridgen.cli import main; t = time.perf_counter(); "
            "rc = main(['run', '-q', sys.argv[1], sys.argv[2]]); "
            "print(time.perf_counter() - t, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(rc)")
    result = subprocess.run([sys.executable, "-c", code, str(config), str(out)], cwd=REPO, capture_output=True,
                            text=True, check=True)
    seconds, rss_kib = result.stdout.split()[-2:]
    return float(seconds), int(rss_kib) // 1024


def overhead(keypoints: int, rounds: int, tmp: Path) -> None:
    from hybridgen.config.config_file import load_config
    from hybridgen.io.integrity import content_digest, verify
    from hybridgen.run.fingerprint import run_fingerprint

    import h5py

    config = tmp / "overhead.yaml"
    config.write_text(config_text(1, 64, 48, keypoints))
    runs, fingerprints, seals, verifies = [], [], [], []
    for round_index in range(rounds):
        out = tmp / f"overhead{round_index}"
        runs.append(_run(config, out)[0])
        loaded = load_config(config, [str(out)])
        start = time.perf_counter()
        run_fingerprint(loaded)
        fingerprints.append(time.perf_counter() - start)
        with h5py.File(out / "data.hdf5", "r") as h5:
            start = time.perf_counter()
            content_digest(h5)
            seals.append(time.perf_counter() - start)
        start = time.perf_counter()
        assert verify(out / "data.hdf5") is None
        verifies.append(time.perf_counter() - start)
        shutil.rmtree(out)
    run, fp, seal, ver = (statistics.median(v) for v in (runs, fingerprints, seals, verifies))
    print(f"{keypoints} keypoints, 64x48 labels (depth, distance, normals, class, instance), gzip 1, "
          f"median of {rounds}:")
    print(f"  whole run (fingerprint and seal included) {run:.2f} s")
    print(f"  fingerprint (config + knot.obj hash)      {fp * 1000:.1f} ms ({100 * fp / run:.2f} %)")
    print(f"  seal (SHA-256 over stored chunks)         {seal * 1000:.1f} ms ({100 * seal / run:.2f} %)")
    print(f"  verify on resume (open + digest)          {ver * 1000:.1f} ms ({100 * ver / run:.2f} % of a run)")


def memory(scene_counts: list[int], tmp: Path) -> None:
    print("labels-only, 16x12, 2 keypoints per scene, one process (workers 1):")
    for scenes in scene_counts:
        config = tmp / f"memory{scenes}.yaml"
        config.write_text(config_text(scenes, 16, 12, 2))
        seconds, rss = _run(config, tmp / f"memory{scenes}")
        print(f"  {scenes:5d} scenes: peak RSS {rss} MiB ({seconds:.1f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keypoints", type=int, default=400)
    parser.add_argument("--scenes", type=int, nargs="+", default=[12, 120])
    parser.add_argument("--rounds", type=int, default=3)
    ns = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        overhead(ns.keypoints, ns.rounds, Path(folder))
        memory(ns.scenes, Path(folder))
    print(f"(load average {open('/proc/loadavg').read().split()[0]}; other work on the machine adds noise)")


if __name__ == "__main__":
    main()
