"""What each ``hybridgen`` command does once its arguments are parsed (:mod:`hybridgen.cli` builds the parser and
handles errors and exit codes). Every heavy import is inside the function that needs it, so ``hybridgen --help``
and argument errors load none of them."""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any

from .errors import InputError, printable
from .logs import LOGGER, log_line


def progress_factory(enabled: bool) -> Any:
    if not enabled:
        return None

    def make(total: int, what: str) -> Any:
        from tqdm import tqdm

        return tqdm(total=total, desc=what, unit="kp", file=sys.stderr, dynamic_ncols=True, leave=True)

    return make


def say(ns: argparse.Namespace, text: str) -> None:
    """A command's result line: on stdout, or (with ``--json``, whose stdout is the JSON line) logged. Bytes
    of a file name that are not UTF-8 show as ``\\xNN`` (:func:`hybridgen.errors.printable`)."""
    text = printable(text)
    if ns.json:
        LOGGER.info(text)
    else:
        print(f"hybridgen: {text}", flush=True)


def parse_shard(text: str | None) -> tuple[int, int] | None:
    if not text:
        return None
    try:
        index, count = (int(v) for v in text.split("/"))
    except ValueError:
        raise InputError(f"--shard takes i/N (e.g. 0/4), got {text!r}") from None
    return index, count


def run_script(ns: argparse.Namespace) -> dict[str, Any]:
    """A BlenderProc 2 script: :func:`hybridgen.bproc.script.run_script` (its own errors: traceback, status 1)."""
    from .bproc.script import run_script

    seconds = run_script(ns.config, ns.args)
    say(ns, f"{ns.config} ran in {seconds:.2f} s")
    return {"script": str(ns.config), "args": list(ns.args), "seconds": round(seconds, 3)}


def cmd_run(ns: argparse.Namespace) -> dict[str, Any]:
    if str(ns.config).endswith(".py"):
        return run_script(ns)
    from .config.notices import set_strict
    from .io.mesh_references import LENIENT_ENV
    from .run.pipeline import run_config

    set_strict(ns.strict)
    if ns.lenient:  # inherited by worker processes, read by the mesh loader
        os.environ[LENIENT_ENV] = "1"
    summary = run_config(ns.config, ns.args, progress=progress_factory(not ns.quiet), log=log_line,
                         workers=ns.workers, shard=parse_shard(ns.shard), executor=ns.executor,
                         address=ns.address, restart=ns.restart, force_resume=ns.force_resume,
                         max_tasks_per_child=ns.max_tasks_per_child)
    from .run.context import printable_text

    outputs = ", ".join(printable_text(str(p)) for p in summary.outputs) or "(no output file)"
    rate = summary.frames / summary.seconds if summary.seconds > 0 else 0.0
    say(ns, f"{summary.frames} keypoint(s) in {summary.seconds:.2f} s ({rate:.1f}/s) -> {outputs}")
    return {"config": str(ns.config), "args": list(ns.args), "keypoints": summary.frames,
            "seconds": round(summary.seconds, 3), "keypoints_per_second": round(rate, 3),
            "outputs": [str(p) for p in summary.outputs]}


def cmd_modules(ns: argparse.Namespace) -> dict[str, Any]:
    from .config.module_listing import describe_aliases, describe_modules, describe_samplers, module_records
    from .config.registry import all_modules, get_module, module_aliases

    if ns.schema is not None:
        return write_schema(ns)
    modules = {ns.name: get_module(ns.name)} if ns.name else all_modules()
    if not ns.json:
        print(describe_modules(modules))
        if not ns.name:
            print(describe_samplers())
            print(describe_aliases())
    return {"modules": module_records(modules), "aliases": module_aliases()}


def write_schema(ns: argparse.Namespace) -> dict[str, Any]:
    from .config.json_schema import config_schema
    from .io.atomic import commit, temporary_path

    text = json.dumps(config_schema(), indent=1) + "\n"
    if ns.schema == "-":
        sys.stdout.write(text)
        return {"schema": "-"}
    target = Path(ns.schema)
    if target.parent != Path("") and not target.parent.is_dir():
        raise InputError(f"--schema: folder '{target.parent}' does not exist")
    temp = temporary_path(target)
    temp.write_text(text)
    commit(temp, target)
    say(ns, f"JSON Schema of the config format written to {target}")
    return {"schema": str(target)}


def cmd_vis(ns: argparse.Namespace) -> dict[str, Any]:
    from .io.visualize import save_contact_sheets

    written = save_contact_sheets(ns.files, ns.save, ns.keys)
    say(ns, f"wrote {len(written)} contact sheet(s) to {ns.save}")
    return {"files": [str(p) for p in written]}


def cmd_gallery(ns: argparse.Namespace) -> dict[str, Any]:
    from .io.gallery import build_gallery

    page = build_gallery(ns.output, keys=ns.keys, limit=ns.limit)
    say(ns, f"gallery written to {page}")
    if ns.open:
        import webbrowser

        webbrowser.open(page.resolve().as_uri())
    return {"page": str(page)}


def cmd_extract(ns: argparse.Namespace) -> dict[str, Any]:
    from .io.extract import extract

    result = extract(ns.files, ns.output_dir, ns.keys, ns.format, ns.depth_scale)
    for note in result.notes:
        LOGGER.warning("note: %s", printable(note))
    say(ns, f"wrote {len(result.files)} file(s) to {ns.output_dir}")
    return {"files": [str(p) for p in result.files]}
