"""The HDF5 writer alone, fed with real label images: where its CPU per keypoint goes, and what each pass costs to
compress (issue 13: end to end vs the raw raster pass).

Run: .venv/bin/python tools/bench_writer.py [--scene "50 objects"] [--resolution 640x480] [--keypoints 120]
         [--compression gzip blosc2] [--skip-codecs]

1. Renders ``--keypoints`` orbit poses of a benchmark scene (tools/label_scenes.py) once, keeping the values the
   default HDF5 file receives (packed targets: float32 depth, octahedral normal codes, narrowed ids, the JSON
   records), then discards the renderer.
2. Stages: writes them ``--rounds`` times per ``--compression`` (alternating) with ``Hdf5SingleFileWriter`` (file
   created, every keypoint written, finalized) and reports the process CPU per keypoint (all threads) and each
   stage's thread CPU per keypoint (the writer's functions wrapped with ``time.thread_time``): shuffle and
   deflate on the compressor pool, chunk hashes, JSON records and the rest of storing on the writer thread.
   Median over rounds.
3. Codecs: per pass, thread CPU and stored bytes per keypoint of ISA-L deflate levels 0-2 with and without HDF5's
   byte shuffle (what the writer stores today: shuffle for float depth, level 1); of Blosc2 frames as the
   writer's ``compression: blosc2`` makes them (codecs, levels, byte/bit shuffle); and of hdf5plugin's Bitshuffle
   and Blosc2 filters compressing inside HDF5.
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any, Callable

from harness import Stopwatch, accumulating, alternating


def capture(scene_name: str, resolution: str, count: int,
            plain: bool = False) -> tuple[tuple[Any, ...], list[dict[str, Any]]]:
    """``(begin arguments, per-keypoint values)`` a default HDF5 file receives for ``count`` orbit poses
    (``plain``: the documented dtypes the renderer makes for a sink that stores nothing encoded)."""
    import label_scenes as bs
    from stored_forms import default_file_encodings

    import hybridgen as hg
    from hybridgen.render.keypoint_loop import run_keypoints
    from hybridgen.render.raster.label_producer import LabelProducer

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
            self.tags = {} if plain else default_file_encodings(n, layouts, records, attributes)
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


def stages(begun: tuple[Any, ...], values: list[dict[str, Any]], rounds: int, compressions: list[str]) -> None:
    """Process CPU and per-stage thread CPU per keypoint of the writer, medians over ``rounds`` files of each of
    ``compressions`` (alternating)."""
    import hybridgen as hg
    import hybridgen.io.hdf5_single as hs

    spent: dict[str, float] = {}

    def timed(name: str, function: Callable[..., Any]) -> Callable[..., Any]:
        return accumulating(spent, name, function, time.thread_time)

    hs.shuffled = timed("shuffle (pool)", hs.shuffled)
    hs.deflate = timed("deflate (pool)", hs.deflate)
    hs.Blosc2Chunks.encode = timed("Blosc2 frames (pool)", hs.Blosc2Chunks.encode)
    hs.Hdf5SingleFileWriter._chunk = timed("pool job in all", hs.Hdf5SingleFileWriter._chunk)
    hs.ChunkStream.add = timed("chunk hashes (writer thread)", hs.ChunkStream.add)
    hs._write_text = timed("JSON records (writer thread)", hs._write_text)
    hs.Hdf5SingleFileWriter._store = timed("writer thread in all", hs.Hdf5SingleFileWriter._store)
    n, layouts, records, attributes = begun
    per_round: dict[str, dict[str, list[float]]] = {c: defaultdict(list) for c in compressions}
    size: dict[str, int] = {}
    for r in range(rounds + 1):  # round 0 untimed: imports (blosc2 ~0.2 s), first allocations
        for compression in alternating(compressions, r):
            spent.clear()
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "data.hdf5"
                watch = Stopwatch()
                writer = hg.Hdf5SingleFileWriter(path, compression=compression)
                writer.begin(n, layouts, records, attributes)
                for index, value in enumerate(values):
                    writer.write(index, value)
                writer.finalize({})
                if r == 0:
                    continue
                wall, cpu = watch.read()
                per_round[compression]["process CPU (all threads)"].append(cpu)
                per_round[compression]["wall"].append(wall)
                size[compression] = path.stat().st_size
            for name, seconds in spent.items():
                per_round[compression][name].append(seconds)
    for compression in compressions:
        print(f"writer alone, compression {compression}, {len(values)} keypoints per file, {rounds} files, medians; "
              f"{size[compression] / len(values) / 1e6:.3f} MB/kp")
        for name, seconds in per_round[compression].items():
            print(f"  {name:32s} {1000 * statistics.median(seconds) / len(values):7.3f} ms/kp")


PASSES = ("depth", "normals", "instance_segmaps", "category_id_segmaps")


def _best(encode: Callable[[Any], int], arrays: list[Any]) -> str:
    """Thread CPU (ms) and stored MB per keypoint of ``encode`` (array -> stored bytes), best of 3 passes."""
    best, size = float("inf"), 0
    for _ in range(3):
        start = time.thread_time()
        size = sum(encode(a) for a in arrays)
        best = min(best, time.thread_time() - start)
    return f"{1000 * best / len(arrays):6.3f} ms {size / len(arrays) / 1e6:6.4f} MB"


def codecs(values: list[dict[str, Any]]) -> None:
    """Per pass: thread CPU and bytes per keypoint of ISA-L levels 0-2, with and without the byte shuffle."""
    from isal import isal_zlib

    from hybridgen.io.hdf5_single import shuffled

    print("per pass, ISA-L deflate (zlib stream, what HDF5's gzip filter reads); best of 3 passes over the keypoints")
    print(f"  {'pass':22s} {'dtype':8s} {'raw MB':>7s}  " + "  ".join(f"{name:>16s}" for name in
                                                                       ("level 0", "level 1", "level 2")))
    for key in PASSES:
        arrays = [getattr(v[key], "stored", v[key]) for v in values if key in v]
        if not arrays:
            continue
        for shuffle in ((False, True) if arrays[0].itemsize > 1 else (False,)):
            cells = [_best(lambda a: len(isal_zlib.compress(shuffled(a) if shuffle else a, level)), arrays)
                     for level in (0, 1, 2)]
            label = key + (" (shuffled)" if shuffle else "")
            print(f"  {label:22s} {str(arrays[0].dtype):8s} {arrays[0].nbytes / 1e6:7.3f}  " + "  ".join(cells))


def old_gzip(values: list[dict[str, Any]]) -> None:
    """MB per keypoint of the old default file - the issue's bytes baseline: the writer before compact storage
    (c55b0fc^: the renderer's float32 normals and int32 ids, each chunk deflated by zlib at level 1, no
    shuffle) - and, for reference, the same arrays with HDF5's shuffle filter on float passes and at level 4.
    ``values``: a ``capture(..., plain=True)``."""
    import zlib

    import numpy as np

    from hybridgen.io.hdf5_single import shuffled

    for shuffle, level in ((False, 1), (False, 4), (True, 1), (True, 4)):
        size = sum(len(zlib.compress(shuffled(a) if shuffle and a.dtype.kind == "f" else a, level))
                   for v in values for a in (np.ascontiguousarray(v[key]) for key in PASSES if key in v))
        what = "the old default writer" if (shuffle, level) == (False, 1) else "variant"
        print(f"plain dtypes, {'shuffle + ' if shuffle else ''}zlib gzip level {level} ({what}): "
              f"{size / len(values) / 1e6:.3f} MB/kp")


BLOSC2_VARIANTS = [("lz4", 1, "byte"), ("lz4", 1, "none"), ("lz4", 1, "bit"), ("lz4", 9, "byte"), ("lz4", 9, "none"),
                   ("lz4hc", 1, "byte"), ("zstd", 1, "byte"), ("zstd", 1, "none"), ("zstd", 1, "bit")]


def blosc2_codecs(values: list[dict[str, Any]]) -> None:
    """Per pass: thread CPU and bytes per keypoint of Blosc2 chunks as the writer makes them (one thread, a
    one-chunk super-chunk frame: what HDF5's Blosc2 filter reads), against ISA-L level 1 (the writer's gzip
    chunks, float depth shuffled first)."""
    from hybridgen.io.blosc2_chunks import Blosc2Chunks
    from hybridgen.io.hdf5_single import deflate, shuffled

    print("per pass, Blosc2 frames (codec level shuffle) vs ISA-L level 1; best of 3 passes over the keypoints")
    for key in PASSES:
        arrays = [getattr(v[key], "stored", v[key]) for v in values if key in v]
        if not arrays:
            continue
        size = arrays[0].itemsize
        print(f"  {key} ({arrays[0].dtype}, {arrays[0].nbytes / 1e6:.3f} MB raw)")
        print(f"    {'ISA-L 1' + (' shuffled' if size > 1 and arrays[0].dtype.kind == 'f' else ''):24s} "
              + _best(lambda a: len(deflate(shuffled(a) if a.dtype.kind == "f" else a, 1)), arrays))
        for codec, level, shuffle in BLOSC2_VARIANTS:
            chunks = Blosc2Chunks(codec, level, shuffle, size)
            print(f"    {f'Blosc2 {codec} {level} {shuffle}':24s} " + _best(lambda a: len(chunks.encode(a)), arrays))


def filter_codecs(values: list[dict[str, Any]]) -> None:
    """Per pass: thread CPU and bytes per keypoint of hdf5plugin's filters compressing inside HDF5 (``dset[i] =
    a`` through the filter, minus the same write unfiltered): the Bitshuffle filter (32008: bitshuffle, then LZ4
    or zstd per block), which has no Python encoder here, next to the Blosc2 filter's own compression. A lower
    bound of each filter's cost: the unfiltered write subtracted also copies the uncompressed bytes into the
    file, the filtered one only the compressed bytes."""
    import h5py
    import hdf5plugin

    filters = {"none": {}, "Bitshuffle lz4": dict(hdf5plugin.Bitshuffle(cname="lz4")),
               "Bitshuffle zstd 1": dict(hdf5plugin.Bitshuffle(cname="zstd", clevel=1)),
               "Blosc2 filter lz4 1 byte": dict(hdf5plugin.Blosc2("lz4", 1, hdf5plugin.Blosc2.SHUFFLE))}
    print("per pass, compressed inside HDF5 by hdf5plugin's filters (CPU minus the unfiltered write: a lower bound); "
          "best of 3")
    for key in PASSES:
        arrays = [getattr(v[key], "stored", v[key]) for v in values if key in v]
        if not arrays:
            continue
        spent: dict[str, float] = {}
        cells = []
        for name, options in filters.items():
            best, size = float("inf"), 0
            for _ in range(3):
                with tempfile.TemporaryDirectory() as tmp, h5py.File(Path(tmp) / "f.hdf5", "w") as h5:
                    dset = h5.create_dataset("x", shape=(len(arrays), *arrays[0].shape), dtype=arrays[0].dtype,
                                             chunks=(1, *arrays[0].shape), **options)
                    start = time.thread_time()
                    for i, a in enumerate(arrays):
                        dset[i] = a
                    best = min(best, time.thread_time() - start)
                    h5.flush()
                    size = sum(dset.id.get_chunk_info(i).size for i in range(len(arrays)))
            spent[name] = best
            if name != "none":
                cells.append(f"{name} {1000 * (best - spent['none']) / len(arrays):6.3f} ms "
                             f"{size / len(arrays) / 1e6:6.4f} MB")
        print(f"  {key:20s} " + "   ".join(cells))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="50 objects", help="a tools/bench_scenes.py scene name")
    parser.add_argument("--resolution", default="640x480", choices=["640x480", "1280x720"])
    parser.add_argument("--keypoints", type=int, default=120, help="keypoints per file")
    parser.add_argument("--rounds", type=int, default=3, help="files written for the stage medians")
    parser.add_argument("--compression", nargs="+", default=["gzip", "blosc2"], choices=["gzip", "blosc2", "none"],
                        help="writer compressions of the stage medians, alternating")
    parser.add_argument("--skip-codecs", action="store_true", help="only the stage medians")
    args = parser.parse_args()
    begun, values = capture(args.scene, args.resolution, args.keypoints)
    print(f"{args.scene}, {args.resolution}")
    stages(begun, values, args.rounds, args.compression)
    if not args.skip_codecs:
        old_gzip(capture(args.scene, args.resolution, 40, plain=True)[1])
        codecs(values[:40])
        blosc2_codecs(values[:40])
        filter_codecs(values[:40])


if __name__ == "__main__":
    main()
