"""The HDF5 writer alone, fed with real label images: where its CPU per keypoint goes, and what each pass costs to
compress (issue 13: end to end vs the raw raster pass).

Run: .venv/bin/python tools/bench_writer.py [--scene "50 objects"] [--resolution 640x480] [--keypoints 120]

1. Renders ``--keypoints`` orbit poses of a benchmark scene (tools/bench_scenes.py) once, keeping the values the
   default HDF5 file receives (packed targets: float32 depth, octahedral normal codes, narrowed ids, the JSON
   records), then discards the renderer.
2. Stages: writes them ``--rounds`` times with ``Hdf5SingleFileWriter`` (file created, every keypoint written,
   finalized) and reports the process CPU per keypoint (all threads) and each stage's thread CPU per keypoint
   (the writer's functions wrapped with ``time.thread_time``): shuffle and deflate on the compressor pool, chunk
   hashes, JSON records and the rest of storing on the writer thread. Median over rounds.
3. Codecs: per pass, thread CPU and stored bytes per keypoint of ISA-L deflate levels 0-2 with and without HDF5's
   byte shuffle (what the writer stores today: shuffle for float depth, level 1).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any, Callable

sys.path.insert(0, str(Path(__file__).resolve().parent))


def capture(scene_name: str, resolution: str, count: int) -> tuple[tuple[Any, ...], list[dict[str, Any]]]:
    """``(begin arguments, per-keypoint values)`` a default HDF5 file receives for ``count`` orbit poses."""
    import bench_scenes as bs

    import hybridgen as hg
    from hybridgen.render.keypoint_loop import run_keypoints
    from hybridgen.render.render_labels import LabelProducer

    scene = bs.ALL_SCENES[scene_name]()
    scene.camera.intrinsics = bs.intrinsics(*bs.RESOLUTIONS[resolution])
    for pose in bs.orbit_poses(scene, count):
        scene.camera.add_keypoint(pose)

    class Capture:
        """Keeps every value, taking the passes in the forms the default HDF5 file stores (asked of one)."""

        def __init__(self) -> None:
            self.values: list[dict[str, Any]] = []
            self.tags: dict[str, str] = {}
            self.begun: tuple[Any, ...] = ()

        def begin(self, n: int, layouts: list[Any], records: dict[str, Any], attributes: dict[str, Any]) -> None:
            with tempfile.TemporaryDirectory() as tmp:
                probe = hg.Hdf5SingleFileWriter(Path(tmp) / "probe.hdf5")
                probe.begin(n, layouts, records, attributes)
                self.tags = probe.accepted_encodings()
                probe.abort()
            self.begun = (n, layouts, records, attributes)

        def accepted_encodings(self) -> dict[str, str]:
            return self.tags

        def write(self, index: int, values: dict[str, Any]) -> None:
            self.values.append(values)

        def end(self) -> None:
            pass

    sink = Capture()
    request = hg.LabelRequest(depth=True, normals=True, map_by=["class", "instance"])
    run_keypoints(scene, [sink], [LabelProducer(scene, request)])
    return sink.begun, sink.values


def stages(begun: tuple[Any, ...], values: list[dict[str, Any]], rounds: int) -> None:
    """Process CPU and per-stage thread CPU per keypoint of the writer, medians over ``rounds`` files."""
    import hybridgen as hg
    import hybridgen.io.hdf5_single as hs

    spent: dict[str, float] = defaultdict(float)

    def timed(name: str, function: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            start = time.thread_time()
            try:
                return function(*args, **kwargs)
            finally:
                spent[name] += time.thread_time() - start
        return wrapper

    hs.shuffled = timed("shuffle (pool)", hs.shuffled)
    hs.deflate = timed("deflate (pool)", hs.deflate)
    hs.Hdf5SingleFileWriter._chunk = timed("pool job in all", hs.Hdf5SingleFileWriter._chunk)
    hs.ChunkStream.add = timed("chunk hashes (writer thread)", hs.ChunkStream.add)
    hs._write_text = timed("JSON records (writer thread)", hs._write_text)
    hs.Hdf5SingleFileWriter._store = timed("writer thread in all", hs.Hdf5SingleFileWriter._store)
    n, layouts, records, attributes = begun
    per_round: dict[str, list[float]] = defaultdict(list)
    for _ in range(rounds):
        spent.clear()
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "data.hdf5"
            cpu, wall = time.process_time(), time.perf_counter()
            writer = hg.Hdf5SingleFileWriter(path)
            writer.begin(n, layouts, records, attributes)
            for index, value in enumerate(values):
                writer.write(index, value)
            writer.finalize({})
            per_round["process CPU (all threads)"].append(time.process_time() - cpu)
            per_round["wall"].append(time.perf_counter() - wall)
            size = path.stat().st_size
        for name, seconds in spent.items():
            per_round[name].append(seconds)
    print(f"writer alone, {len(values)} keypoints per file, {rounds} files, medians; {size / len(values) / 1e6:.3f}"
          " MB/kp")
    for name, seconds in per_round.items():
        print(f"  {name:32s} {1000 * statistics.median(seconds) / len(values):7.3f} ms/kp")


def codecs(values: list[dict[str, Any]]) -> None:
    """Per pass: thread CPU and bytes per keypoint of ISA-L levels 0-2, with and without the byte shuffle."""
    from isal import isal_zlib

    from hybridgen.io.hdf5_single import shuffled

    print("per pass, ISA-L deflate (zlib stream, what HDF5's gzip filter reads); best of 3 passes over the keypoints")
    print(f"  {'pass':22s} {'dtype':8s} {'raw MB':>7s}  " + "  ".join(f"{name:>16s}" for name in
                                                                       ("level 0", "level 1", "level 2")))
    for key in ("depth", "normals", "instance_segmaps", "category_id_segmaps"):
        arrays = [getattr(v[key], "stored", v[key]) for v in values if key in v]
        if not arrays:
            continue
        for shuffle in ((False, True) if arrays[0].itemsize > 1 else (False,)):
            cells = []
            for level in (0, 1, 2):
                best, sizes = float("inf"), 0
                for _ in range(3):
                    start = time.thread_time()
                    sizes = sum(len(isal_zlib.compress(shuffled(a) if shuffle else a, level)) for a in arrays)
                    best = min(best, time.thread_time() - start)
                cells.append(f"{1000 * best / len(arrays):6.3f} ms {sizes / len(arrays) / 1e6:6.4f} MB")
            label = key + (" (shuffled)" if shuffle else "")
            print(f"  {label:22s} {str(arrays[0].dtype):8s} {arrays[0].nbytes / 1e6:7.3f}  " + "  ".join(cells))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="50 objects", help="a tools/bench_scenes.py scene name")
    parser.add_argument("--resolution", default="640x480", choices=["640x480", "1280x720"])
    parser.add_argument("--keypoints", type=int, default=120, help="keypoints per file")
    parser.add_argument("--rounds", type=int, default=3, help="files written for the stage medians")
    args = parser.parse_args()
    begun, values = capture(args.scene, args.resolution, args.keypoints)
    print(f"{args.scene}, {args.resolution}")
    stages(begun, values, args.rounds)
    codecs(values[:40])


if __name__ == "__main__":
    main()
