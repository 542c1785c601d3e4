"""The ``hybridgen`` command line.

Commands: ``run`` (a config), ``modules`` (what a config may use; ``--schema`` for editors), ``vis``
(contact sheets), ``gallery`` (an HTML page of an output), ``extract`` (image/array files). Global options
(``--debug``, ``-v``, ``-q``, ``--json``) go before or after the command.

Messages go through :mod:`logging` (logger ``hybridgen``, see :mod:`hybridgen.logs`). User errors (config,
input, missing system libraries) are one line on stderr and exit status 2; ``--debug`` shows the
traceback instead. With ``--json`` the last line on stdout is one JSON object summarising the command
(``"status": "ok"`` or ``"error"``), for schedulers and scripts.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import Any, Callable, Sequence

from ._version import __version__
from .errors import HybridgenError, fault_message, printable
from .logs import LOGGER, configure, level_for
from . import cli_commands as commands
from .run.executor import DEFAULT_MAX_TASKS_PER_CHILD, EXECUTORS

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130

DESCRIPTION = """\
hybridgen generates synthetic training data: path-traced color (Mitsuba 3) and exact rasterized labels
(depth, distance, normals, segmentation, ...) for the camera keypoints of scenes built by a YAML config in
BlenderProc's format. Conventions: docs/conventions.md in the repository."""

EPILOG = """\
examples:
  hybridgen run configs/quickstart.yaml output/quickstart      render a config (<args:0> = output folder)
  hybridgen run CONFIG OUT --workers 4 --json                  in parallel, one JSON summary line at the end
  hybridgen modules loader.ObjLoader                           one module's parameters
  hybridgen modules --schema config.schema.json                a JSON Schema for editors
  hybridgen vis output/quickstart/data.hdf5 --save preview/    contact sheets
  hybridgen gallery output/quickstart --open                   an HTML page of every pass

Errors print one line naming file, module and key and exit with status 2 (--debug: the traceback)."""


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Keeps the description's and epilog's own line breaks; wraps option help at the terminal width."""


def _script_arguments(argv: list[str]) -> list[str] | None:
    """For ``run SCRIPT.py ARGS...``: take everything after the script out of ``argv`` and return it (the script's
    own arguments, options included, as ``blenderproc run`` passes them); None for any other command line."""
    commands = [i for i, arg in enumerate(argv) if not arg.startswith("-")]
    if not commands or argv[commands[0]] != "run" or len(commands) < 2 or not argv[commands[1]].endswith(".py"):
        return None
    tail = argv[commands[1] + 1:]
    del argv[commands[1] + 1:]
    return tail


def _add_global_options(parser: argparse.ArgumentParser, *, in_command: bool) -> None:
    """``--debug -v -q --json``; inside a command they default to 'not given' so that the values given
    before the command stay (``hybridgen --debug run ...`` and ``hybridgen run ... --debug`` are the same)."""
    unset: dict[str, Any] = {"default": argparse.SUPPRESS} if in_command else {}
    group = parser.add_argument_group("global options (before or after the command)")
    group.add_argument("--debug", action="store_true", help="show the traceback of an error", **unset)
    group.add_argument("-v", "--verbose", action="count", help="more messages (debug level); repeatable",
                       **(unset or {"default": 0}))
    group.add_argument("-q", "--quiet", action="store_true",
                       help="on stderr only warnings and errors (no progress bars, no status messages)", **unset)
    group.add_argument("--json", action="store_true",
                       help="end with one JSON summary line on stdout (status, outputs, timings)", **unset)


def _command(sub: Any, name: str, func: Callable[[argparse.Namespace], dict[str, Any]], summary: str,
             description: str) -> argparse.ArgumentParser:
    """The sub-command ``name`` that calls ``func``, with the global options."""
    parser = sub.add_parser(name, help=summary, description=description, formatter_class=_HelpFormatter)
    _add_global_options(parser, in_command=True)
    parser.set_defaults(func=func)
    return parser


def _reader_command(sub: Any, name: str, func: Callable[[argparse.Namespace], dict[str, Any]], summary: str,
                    description: str, inputs: tuple[str, str | None, str], keys: str) -> argparse.ArgumentParser:
    """A command that reads outputs: its positional ``inputs`` (name, nargs, help) and ``--keys`` (the passes
    it works on, ``keys`` says what it does with them; default: every image key)."""
    parser = _command(sub, name, func, summary, description)
    input_name, nargs, input_help = inputs
    parser.add_argument(input_name, nargs=nargs, help=input_help)
    parser.add_argument("--keys", nargs="+", help=f"{keys} (default: every image key)")
    return parser


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hybridgen", description=DESCRIPTION, epilog=EPILOG,
                                     formatter_class=_HelpFormatter)
    parser.add_argument("--version", action="version", version=f"hybridgen {__version__}")
    _add_global_options(parser, in_command=False)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = _command(sub, "run", commands.cmd_run, "run a config (or a BlenderProc 2 script) and write its outputs",
                   "Run CONFIG; the values after it fill <args:0>, <args:1>, ... in the config.\n"
                   "Rerunning the same command resumes: complete work units are verified and kept.\n"
                   "A .py CONFIG is a BlenderProc 2 script, run as 'blenderproc run main.py ARGS...' runs it:\n"
                   "everything after it is the script's sys.argv[1:] (docs/blenderproc.md).")
    run.add_argument("config", help="YAML config file, or a BlenderProc 2 script (.py)")
    run.add_argument("args", nargs="*", help="values for <args:0>, <args:1>, ... (e.g. the output folder)")
    run.add_argument("--lenient", action="store_true", help="render meshes whose MTL or texture files are "
                     "missing (a notice) instead of stopping with an error")
    run.add_argument("--strict", action="store_true", help="every notice (a BlenderProc key or setting hybridgen "
                     "accepts but handles differently) is an error")
    run.add_argument("--workers", type=int, default=1, help="processes running work units in parallel (default 1)")
    run.add_argument("--shard", metavar="I/N",
                     help="run only the scenes with scene %% N == I (for SLURM arrays and indexed jobs)")
    run.add_argument("--executor", default=EXECUTORS[0], choices=EXECUTORS,
                     help="where work units run: a local process pool (default) or Ray")
    run.add_argument("--address", help="address of a running Ray cluster (with --executor ray; default: "
                     "start a local one)")
    run.add_argument("--restart", action="store_true",
                     help="discard existing outputs of this config (shards, data.hdf5) instead of resuming")
    run.add_argument("--force-resume", action="store_true",
                     help="reuse existing outputs that verify even if another config or other inputs made them "
                     "(the result then mixes both)")
    run.add_argument("--max-tasks-per-child", type=int, default=DEFAULT_MAX_TASKS_PER_CHILD,
                     help="work units a pool worker renders before it is replaced (bounds memory growth)")

    modules = _command(sub, "modules", commands.cmd_modules, "list modules, their parameters and the samplers",
                       "List every module a config may name, with each parameter's type, unit, default, allowed\n"
                       "choices and whether it may be a sampler; then the samplers with their parameters.")
    modules.add_argument("name", nargs="?", help="show only this module")
    modules.add_argument("--schema", nargs="?", const="-", metavar="FILE",
                         help="write a JSON Schema of the config format to FILE (or stdout) for editors")

    vis = _reader_command(sub, "vis", commands.cmd_vis, "save a contact sheet PNG per keypoint of HDF5 outputs",
                          "Save one PNG per keypoint showing its color and label passes side by side.",
                          ("files", "+", "HDF5 files written by hybridgen (either layout)"), "keys to show")
    vis.add_argument("--save", required=True, help="folder for the PNG files")

    gallery = _reader_command(
        sub, "gallery", commands.cmd_gallery, "write a static HTML page of an output folder",
        "Write OUT/gallery/index.html: thumbnails of every pass of every keypoint with legends,\n"
        "click to enlarge, filters by scene and keypoint. No server or network needed.",
        ("output", None, "output folder (data.hdf5 or BlenderProc <i>.hdf5 files) or HDF5 file"), "passes to show")
    gallery.add_argument("--open", action="store_true", help="open the page in the default web browser")
    gallery.add_argument("--limit", type=int, help="show only the first N keypoints")

    ext = _reader_command(sub, "extract", commands.cmd_extract, "write the keys of HDF5 outputs as PNG, EXR or npy files",
                          "Write each keypoint's keys as files: PNG (8-bit images, 16-bit ids, depth and distance as\n"
                          "16-bit millimetres), EXR (the stored floats) or npy (the stored arrays).",
                          ("files", "+", "HDF5 files (single-file or BlenderProc <i>.hdf5 layout)"), "keys to extract")
    ext.add_argument("--output_dir", required=True, help="folder for the extracted files")
    ext.add_argument("--format", choices=("png", "npy", "exr"), default="png",
                     help="png: 8-bit images, 16-bit ids, depth/distance as 16-bit mm, flow as 16-bit KITTI; "
                     "npy: the stored arrays; exr: the stored floats (default: png)")
    ext.add_argument("--depth_scale", type=float, default=1.0,
                     help="png only: depth/distance PNG value * depth_scale = mm (default 1.0)")
    return parser


def _json_line(ns: argparse.Namespace, status: str, started: float, **fields: Any) -> None:
    record = {"status": status, "command": ns.command, "version": __version__,
              "wall_seconds": round(time.perf_counter() - started, 3), **fields}
    print(json.dumps(record, sort_keys=False), flush=True)


def main(argv: Sequence[str] | None = None) -> int:
    arguments = list(sys.argv[1:] if argv is None else argv)
    script_arguments = _script_arguments(arguments)
    ns = build_parser().parse_args(arguments)
    if script_arguments is not None:
        ns.args = script_arguments
    configure(level_for(ns.verbose, ns.quiet))
    started = time.perf_counter()
    try:
        result = ns.func(ns)
    except HybridgenError as exc:
        if ns.debug:
            raise
        LOGGER.error("%s", printable(str(exc)))
        if ns.json:
            _json_line(ns, "error", started, exit_code=EXIT_USER_ERROR, error=printable(str(exc)))
        return EXIT_USER_ERROR
    except BrokenPipeError:  # the reader of stdout went away (`hybridgen modules | head`): stop quietly
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - Python flushes stdout at exit
        return 0
    except (OSError, RuntimeError) as exc:  # the machine's state (disk full, name too long ...): one line too
        message = fault_message(exc)
        if message is None or ns.debug:
            raise
        message = printable(message)
        LOGGER.error("%s", message)
        if ns.json:
            _json_line(ns, "error", started, exit_code=EXIT_USER_ERROR, error=message)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        LOGGER.error("interrupted; no output was committed for unfinished writers")
        if ns.json:
            _json_line(ns, "interrupted", started, exit_code=EXIT_INTERRUPTED)
        return EXIT_INTERRUPTED
    if ns.json:
        _json_line(ns, "ok", started, **result)
    return 0


def console_main() -> None:
    """The ``hybridgen`` command (console script, ``python -m hybridgen``): :func:`main`, then the process ends
    through :func:`hybridgen.process_exit.end_process` (a successful run skips the interpreter's teardown)."""
    from .process_exit import end_process

    end_process(main())


if __name__ == "__main__":
    console_main()
