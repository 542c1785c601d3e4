"""The command line shared by tools that store the real BlenderProc's answers as a JSON table for a test
(tools/urdf_table.py, tools/bproc_pose_pattern_calibration.py): each tool has an ``inner`` part run inside an
engine's interpreter (``blenderproc``: ``.venv-blenderproc`` with BlenderProc's source, tools/blenderproc_reference.py;
``hybridgen``: this Python) that writes the engine's table, and a ``differences`` that compares two tables.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable

from blenderproc_reference import REPO, reference_invocation


def run_inner(tool: Path, engine: str, args: list[str], out: Path) -> dict:
    """Runs ``tool --inner ENGINE ARGS... OUT`` in that engine's interpreter (``blenderproc``: the venv's Python
    with BlenderProc's source, as :func:`reference_invocation`; else this Python) and returns the JSON table it
    wrote to ``out``; without one, exits with the tail of its output."""
    if engine == "blenderproc":
        invocation = reference_invocation("x", [], root=REPO)
        command, env = [invocation.command[0]], invocation.env
    else:
        command, env = [sys.executable], dict(os.environ)
    done = subprocess.run([*command, str(tool), "--inner", engine, *args, str(out)], env=env, capture_output=True,
                          text=True, check=False)
    if not out.is_file():
        sys.exit(f"{engine} made no table (exit {done.returncode}): {(done.stdout + done.stderr)[-3000:]}")
    return json.loads(out.read_text())


def table_tool(tool: Path, doc: str, store: Path, inner: Callable[..., None],
               differences: Callable[[dict, dict], list[str]], inputs: Callable[[], Any] | None = None) -> None:
    """The command line of a tool that stores the real BlenderProc's answers as a JSON table for a test:
    ``--inner ENGINE [INPUTS] OUT`` calls ``inner`` (inside an engine's interpreter); otherwise the table of
    BlenderProc (given ``inputs()`` as a JSON file, when there are inputs) is written to ``--store`` (default
    ``store``) and, with ``--compare``, hybridgen's table is made too and ``differences`` printed."""
    if len(sys.argv) > 1 and sys.argv[1] == "--inner":
        inner(*sys.argv[2:])
        return
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--store", default=str(store))
    parser.add_argument("--compare", action="store_true", help="also run hybridgen and print the differences")
    ns = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        args = []
        if inputs is not None:
            (Path(folder) / "inputs.json").write_text(json.dumps(inputs()))
            args = [str(Path(folder) / "inputs.json")]
        reference = run_inner(tool, "blenderproc", args, Path(folder) / "blenderproc.json")
        Path(ns.store).parent.mkdir(parents=True, exist_ok=True)
        Path(ns.store).write_text(json.dumps(reference, indent=1) + "\n")
        print(f"stored {ns.store}")
        if ns.compare:
            ours = run_inner(tool, "hybridgen", args, Path(folder) / "hybridgen.json")
            print("\n".join(differences(reference, ours)))
