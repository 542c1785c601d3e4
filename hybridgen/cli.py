"""Command line: ``hybridgen run CONFIG [ARGS...]``, ``modules [NAME]``, ``vis FILE... --save DIR``,
``extract FILE... --output_dir DIR``, ``--version``.

User errors (config, input, missing system libraries) print one line to stderr and exit with status 2;
``--debug`` shows the traceback instead.
"""
from __future__ import annotations

import argparse
import sys
from typing import Any, Sequence

from ._version import __version__
from .errors import HybridgenError, InputError

EXIT_USER_ERROR = 2


def _progress_factory(enabled: bool) -> Any:
    if not enabled:
        return None

    def make(total: int, what: str) -> Any:
        from tqdm import tqdm

        return tqdm(total=total, desc=what, unit="kp", file=sys.stderr, dynamic_ncols=True, leave=True)

    return make


def _cmd_run(ns: argparse.Namespace) -> int:
    from .run.pipeline import run_config

    log = None if ns.quiet else (lambda message: print(f"hybridgen: {message}", file=sys.stderr, flush=True))
    shard = None
    if ns.shard:
        try:
            index, count = (int(v) for v in ns.shard.split("/"))
        except ValueError:
            raise InputError(f"--shard takes i/N (e.g. 0/4), got {ns.shard!r}") from None
        shard = (index, count)
    summary = run_config(ns.config, ns.args, progress=_progress_factory(not ns.quiet), log=log, workers=ns.workers,
                         shard=shard, executor=ns.executor, address=ns.address, restart=ns.restart,
                         force_resume=ns.force_resume, max_tasks_per_child=ns.max_tasks_per_child)
    outputs = ", ".join(str(p) for p in summary.outputs) or "(no output file)"
    rate = summary.frames / summary.seconds if summary.seconds > 0 else 0.0
    print(f"hybridgen: {summary.frames} keypoint(s) in {summary.seconds:.2f} s ({rate:.1f}/s) -> {outputs}")
    return 0


def _cmd_modules(ns: argparse.Namespace) -> int:
    from .config.registry import all_modules, get_module

    modules = {ns.name: get_module(ns.name)} if ns.name else all_modules()
    for name, cls in modules.items():
        doc = (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""
        print(f"{name}: {doc}")
        for param in cls.params:
            print(f"    {param.describe()}")
        print()
    return 0


def _cmd_vis(ns: argparse.Namespace) -> int:
    from .io.visualize import save_contact_sheets

    written = save_contact_sheets(ns.files, ns.save, ns.keys)
    print(f"hybridgen: wrote {len(written)} contact sheet(s) to {ns.save}")
    return 0


def _cmd_gallery(ns: argparse.Namespace) -> int:
    from .io.gallery import build_gallery

    page = build_gallery(ns.output, keys=ns.keys, limit=ns.limit)
    print(f"hybridgen: gallery written to {page}")
    if ns.open:
        import webbrowser

        webbrowser.open(page.resolve().as_uri())
    return 0


def _cmd_extract(ns: argparse.Namespace) -> int:
    from .io.extract import extract

    result = extract(ns.files, ns.output_dir, ns.keys, ns.format, ns.depth_scale)
    for note in result.notes:
        print(f"hybridgen: note: {note}", file=sys.stderr)
    print(f"hybridgen: wrote {len(result.files)} file(s) to {ns.output_dir}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hybridgen", description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--version", action="version", version=f"hybridgen {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a config: hybridgen run CONFIG [ARGS...] (ARGS fill <args:N>)")
    run.add_argument("config", help="YAML config file")
    run.add_argument("args", nargs="*", help="values for <args:0>, <args:1>, ...")
    run.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    run.add_argument("--workers", type=int, default=1, help="processes running work units in parallel")
    run.add_argument("--shard", help="i/N: run only the scenes with scene %% N == i (external schedulers)")
    run.add_argument("--executor", default="pool", choices=("pool", "ray"), help="where work units run")
    run.add_argument("--address", help="Ray cluster address (with --executor ray); default: a local cluster")
    run.add_argument("--restart", action="store_true",
                     help="discard existing outputs of this config (shards, data.hdf5) instead of resuming")
    run.add_argument("--force-resume", action="store_true",
                     help="reuse existing outputs that verify even if another config or other inputs made them "
                     "(the result then mixes both)")
    run.add_argument("--max-tasks-per-child", type=int, default=25,
                     help="work units a pool worker renders before it is replaced (bounds memory growth)")
    run.set_defaults(func=_cmd_run)
    modules = sub.add_parser("modules", help="list modules and their parameters")
    modules.add_argument("name", nargs="?", help="show one module")
    modules.set_defaults(func=_cmd_modules)
    vis = sub.add_parser("vis", help="save a contact sheet PNG per keypoint of HDF5 outputs")
    vis.add_argument("files", nargs="+", help="HDF5 files written by hybridgen")
    vis.add_argument("--keys", nargs="+", help="keys to show (default: every image key)")
    vis.add_argument("--save", required=True, help="folder for the PNG files")
    vis.set_defaults(func=_cmd_vis)
    gallery = sub.add_parser("gallery", help="write a static HTML page of an output folder (OUT/gallery/index.html): "
                             "thumbnails of every pass, legends, click to enlarge, scene/keypoint filters")
    gallery.add_argument("output", help="output folder (data.hdf5 or BlenderProc <i>.hdf5 files) or HDF5 file")
    gallery.add_argument("--open", action="store_true", help="open the page in the default web browser")
    gallery.add_argument("--keys", nargs="+", help="passes to show (default: every image key)")
    gallery.add_argument("--limit", type=int, help="show only the first N keypoints")
    gallery.set_defaults(func=_cmd_gallery)
    ext = sub.add_parser("extract", help="write each keypoint's keys of HDF5 outputs as PNG / 16-bit PNG / EXR / npy "
                         "files (depth and distance PNGs in mm)")
    ext.add_argument("files", nargs="+", help="HDF5 files (single-file or BlenderProc <i>.hdf5 layout)")
    ext.add_argument("--output_dir", required=True, help="folder for the extracted files")
    ext.add_argument("--keys", nargs="+", help="keys to extract (default: every image key)")
    ext.add_argument("--format", choices=("png", "npy", "exr"), default="png",
                     help="png: 8-bit images, 16-bit ids, depth/distance as 16-bit mm, flow as 16-bit KITTI; "
                     "npy: the stored arrays; exr: the stored floats (default: png)")
    ext.add_argument("--depth_scale", type=float, default=1.0,
                     help="png only: depth/distance PNG value * depth_scale = mm (default 1.0)")
    ext.set_defaults(func=_cmd_extract)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    parser = build_parser()
    ns = parser.parse_args(argv)
    try:
        return int(ns.func(ns))
    except HybridgenError as exc:
        if debug:
            raise
        print(f"hybridgen: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("hybridgen: interrupted; no output was committed for unfinished writers", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
