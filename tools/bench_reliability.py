"""What reliability costs: fingerprints, checksums and staged (resumable) writing on a 400-keypoint labels
run, and peak memory of a labels-only run over 12 vs 120 scenes (memory must not grow with the number of
scenes).

Run: .venv/bin/python tools/bench_reliability.py [--keypoints 400] [--size 128 96] [--scenes 12 120]
     [--rounds 5]

Three variants of one config run in fresh processes, interleaved round by round (so load from other work
hits them alike), each timed around ``hybridgen run`` (wall and CPU seconds, interpreter start excluded):

- ``bare``: a direct write without the reliability work - no input file hashes in the fingerprint, no
  ``content_sha256`` seal (both patched out in the child);
- ``direct``: a direct write (``resume_chunk_keypoints: 0`` behaviour: one file streamed by the writer);
- ``staged``: the default - keypoints rendered in verified, fingerprinted parts and merged into the same
  bytes (the benchmark checks that ``staged`` and ``direct`` wrote identical files).

All three run the same config text (the part size is patched in the child, so the fingerprint and thus the
bytes agree). The steps are also timed one by one on the outputs in this process: computing the fingerprint
(config leaves and input file hashes: every input read, and from the identity cache of
:mod:`hybridgen.run.input_hashes` as every run after the first does), sealing (SHA-256 over the stored
chunks) and verifying (what a resume does per existing file); and the fingerprint of a config naming a
folder of 2000 files, hashed vs cached. Peak RSS is ``ru_maxrss`` of the run's process.
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from harness import medians, run_process
from scene_yaml import knot_config

REPO = Path(__file__).resolve().parents[1]

VARIANTS = ("bare", "direct", "staged")
_PATCHES = {
    "bare": ("import hybridgen.io.integrity as integrity, hybridgen.run.fingerprint as fingerprint, "
             "hybridgen.run.staged_output as staged; integrity.content_digest = lambda h5, streams=None: 'unsealed'; "
             "fingerprint.input_files = lambda config: []; staged.part_keypoints = lambda requested, traces: 0"),
    "direct": "import hybridgen.run.staged_output as staged; staged.part_keypoints = lambda requested, traces: 0",
    "staged": "pass",
}
_CHILD = ("import json, resource, sys, time; {patch}; from hybridgen.cli import main; "
          "t = time.perf_counter(); c = time.process_time(); rc = main(['run', '-q', sys.argv[1], sys.argv[2]]); "
          "print(json.dumps({{'wall': time.perf_counter() - t, 'cpu': time.process_time() - c, "
          "'rss_kib': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}})); sys.exit(rc)")


def config_text(scenes: int, width: int, height: int, keypoints: int) -> str:
    """The run benchmarks' labels-only knot scene (knot over a floor, sampled cameras, depth/distance/normals/ids;
    tools/scene_yaml.py)."""
    return knot_config("labels", scenes, width=width, height=height, keypoints=keypoints)


def _run(config: Path, out: Path, variant: str = "staged") -> dict[str, float]:
    """Wall and CPU seconds of ``hybridgen run`` (measured in the child, around the call) and the child's peak RSS
    (``rss``, MiB) of one run into ``out`` in a fresh process."""
    shutil.rmtree(out, ignore_errors=True)
    code = _CHILD.format(patch=_PATCHES[variant])
    report = run_process([sys.executable, "-c", code, str(config), str(out)], cwd=REPO).report
    assert report is not None, f"the {variant} run printed no report"
    return {"wall": report["wall"], "cpu": report["cpu"], "rss": int(report["rss_kib"]) // 1024}


def _components(config: Path, out: Path) -> dict[str, float]:
    """Seconds of the reliability steps, timed one by one on ``out``'s data.hdf5."""
    import h5py

    from hybridgen.config.config_file import load_config
    from hybridgen.io.integrity import content_digest, verify
    from hybridgen.run.fingerprint import run_fingerprint
    from hybridgen.run.input_hashes import InputHashes

    loaded = load_config(config, [str(out)])
    times = {}
    for name, hashes in (("fingerprint", InputHashes(None)), ("fingerprint (cached)", InputHashes.default())):
        start = time.perf_counter()
        run_fingerprint(loaded, hashes)
        times[name] = time.perf_counter() - start
    with h5py.File(out / "data.hdf5", "r") as h5:
        start = time.perf_counter()
        content_digest(h5)
        times["seal"] = time.perf_counter() - start
    start = time.perf_counter()
    assert verify(out / "data.hdf5") is None
    times["verify"] = time.perf_counter() - start
    return times


def _differing_chunks(first: Path, second: Path) -> list[str] | None:
    """``[]`` when the files are byte-identical; else the ``key[index]`` of stored chunks whose bytes differ
    while the decoded datasets are equal; None when any decoded value or attribute differs."""
    import h5py
    import numpy as np

    if first.read_bytes() == second.read_bytes():
        return []
    differing = []
    with h5py.File(first, "r") as a, h5py.File(second, "r") as b:
        if set(a) != set(b):
            return None
        for key in a:
            x, y = np.asarray(a[key][()]), np.asarray(b[key][()])
            if x.dtype.kind in "SOU":
                if x.tolist() != y.tolist():
                    return None
            elif not np.array_equal(x, y, equal_nan=x.dtype.kind == "f"):
                return None
            if a[key].chunks:
                tail = (0,) * (a[key].ndim - 1)
                for index in range(a[key].shape[0]):
                    info = a[key].id.get_chunk_info_by_coord((index, *tail))
                    if info.byte_offset is not None and \
                            a[key].id.read_direct_chunk((index, *tail)) != b[key].id.read_direct_chunk((index, *tail)):
                        differing.append(f"{key}[{index}]")
    return differing


def overhead(keypoints: int, size: tuple[int, int], rounds: int, tmp: Path) -> None:
    config = tmp / "overhead.yaml"
    config.write_text(config_text(1, size[0], size[1], keypoints))
    runs: dict[str, list[dict[str, float]]] = {variant: [] for variant in VARIANTS}
    mismatches: list[list[str]] = []
    steps: dict[str, list[float]] = {}
    for _ in range(rounds):
        for variant in VARIANTS:  # one output folder for all (a file records where it was written)
            runs[variant].append(_run(config, tmp / "out", variant))
            shutil.rmtree(tmp / variant, ignore_errors=True)
            (tmp / "out").rename(tmp / variant)
        differing = _differing_chunks(tmp / "direct/data.hdf5", tmp / "staged/data.hdf5")
        if differing is None:
            raise SystemExit("the staged run's data.hdf5 holds other data than the direct write's")
        mismatches.append(differing)
        for name, seconds in _components(config, tmp / "direct").items():
            steps.setdefault(name, []).append(seconds)
    middle = {v: medians(runs[v]) for v in VARIANTS}
    wall, cpu = {v: middle[v]["wall"] for v in VARIANTS}, {v: middle[v]["cpu"] for v in VARIANTS}
    print(f"{keypoints} keypoints, {size[0]}x{size[1]} labels (depth, distance, normals, class, instance), gzip 1, "
          f"median of {rounds} interleaved rounds (wall / CPU seconds of `hybridgen run`, imports included):")
    for variant in VARIANTS:
        print(f"  {variant:<7} {wall[variant]:6.2f} s wall {cpu[variant]:6.2f} s CPU   "
              "(walls " + ", ".join(f"{r['wall']:.2f}" for r in runs[variant]) + ")")
    print(f"  fingerprint + checksums (direct / bare): {wall['direct'] / wall['bare']:.3f}x wall, "
          f"{cpu['direct'] / cpu['bare']:.3f}x CPU")
    print(f"  staged / direct:                          {wall['staged'] / wall['direct']:.3f}x wall, "
          f"{cpu['staged'] / cpu['direct']:.3f}x CPU")
    same = sum(not m for m in mismatches)
    print(f"  staged file byte-identical to the direct one in {same} of {rounds} rounds"
          + ("" if same == rounds else f" (decoded data equal; compressed chunks differing: "
             f"{sorted({c for m in mismatches for c in m})} - the deflate stream of identical input varied)"))
    print("  steps timed alone (median), share of the direct run's wall time:")
    for name, values in steps.items():
        seconds = statistics.median(values)
        print(f"    {name:<22} {seconds * 1000:7.1f} ms ({100 * seconds / wall['direct']:.2f} %)")


def folder_fingerprint(files: int, kib: int, tmp: Path) -> None:
    """The fingerprint of a config naming a folder of ``files`` files: hashing all of them (first run) vs
    the identity cache of :mod:`hybridgen.run.input_hashes` (every later run)."""
    import os

    from hybridgen.config.config_file import load_config
    from hybridgen.run.fingerprint import run_fingerprint
    from hybridgen.io.file_identity import SETTLE_NS
    from hybridgen.run.input_hashes import InputHashes

    folder = tmp / "textures"
    folder.mkdir()
    for index in range(files):
        (folder / f"{index:05d}.png").write_bytes(os.urandom(kib * 1024))
    config = tmp / "folder.yaml"
    config.write_text(f"modules:\n  - name: material.MaterialRandomizer\n    config: {{textures: {folder}}}\n")
    loaded = load_config(config)
    time.sleep(SETTLE_NS / 1e9 + 0.1)  # files written just now are hashed but not remembered
    cache = tmp / "input_hashes.json"
    times = []
    for _ in range(3):
        hashes = InputHashes(cache)
        start = time.perf_counter()
        run_fingerprint(loaded, hashes)
        times.append((time.perf_counter() - start, hashes.hashed))
    print(f"fingerprint of a named folder of {files} files x {kib} KiB (page cache warm):")
    print(f"  every file hashed: {times[0][0] * 1000:.0f} ms; from the identity cache: "
          f"{min(t for t, _ in times[1:]) * 1000:.0f} ms ({times[-1][1]} file(s) read)")


def memory(scene_counts: list[int], tmp: Path) -> None:
    print("labels-only, 16x12, 2 keypoints per scene, one process (workers 1):")
    for scenes in scene_counts:
        config = tmp / f"memory{scenes}.yaml"
        config.write_text(config_text(scenes, 16, 12, 2))
        run = _run(config, tmp / f"memory{scenes}")
        print(f"  {scenes:5d} scenes: peak RSS {run['rss']} MiB ({run['wall']:.1f} s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keypoints", type=int, default=400)
    parser.add_argument("--size", type=int, nargs=2, default=[128, 96], metavar=("WIDTH", "HEIGHT"))
    parser.add_argument("--scenes", type=int, nargs="*", default=[12, 120])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--folder-files", type=int, default=2000)
    ns = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        overhead(ns.keypoints, tuple(ns.size), ns.rounds, Path(folder))
        folder_fingerprint(ns.folder_files, 64, Path(folder))
        memory(ns.scenes, Path(folder))
    print(f"(load average {open('/proc/loadavg').read().split()[0]}; other work on the machine adds noise)")


if __name__ == "__main__":
    main()
