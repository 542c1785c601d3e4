"""Run every BlenderProc 2 example script (``examples/**/main.py``) of a BlenderProc checkout with hybridgen,
unchanged, and report one line per example.

    .venv/bin/python tools/check_blenderproc_scripts.py PATH [--tag v.2.8.0] [--only SUBSTRING]
        [--timeout S] [--max-samples N]

PATH is a BlenderProc working tree or a bare git mirror read at ``--tag`` (files copied into a temporary folder
with ``git show``, as tools/check_blenderproc_configs.py does; nothing of BlenderProc is stored in this
repository). Each script runs as its README's ``blenderproc run examples/.../main.py ARGS`` line says, from the
checkout's root, as ``hybridgen run examples/.../main.py ARGS`` in its own process: an argument naming a file
the checkout has is that file, one naming an output folder is a temporary folder, any other (datasets to
download, files the mirror lacks) a stand-in of check_blenderproc_configs.make_standins (a scene.obj, a camera
file, BOP datasets, textures) by its name. ``--max-samples N`` caps the color samples per pixel
(``HYBRIDGEN_BPROC_MAX_SAMPLES``) for a slow or shared machine.

Each example gets ``runs`` or ``fails: <the last line of its error>``; exit status 0 always.
"""
from __future__ import annotations

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TOOLS = Path(__file__).resolve().parent
sys.path.insert(0, str(TOOLS))

from check_blenderproc_configs import example_configs, make_standins  # noqa: E402
from bproc_dataset_standins import copy_resources, dataset_arg, make_dataset_standins, run_lines  # noqa: E402

REPO = TOOLS.parent
RUN_LINE = re.compile(r"blenderproc run (examples/\S+/main\.py)([^\n`]*)")
PLACEHOLDER = re.compile(r"<([^<>]+)>")


def readme_args(script: Path, root: Path) -> list[str]:
    """The arguments of the README's ``blenderproc run <this script> ...`` line with the most of them (none when
    it has none)."""
    readme = script.parent / "README.md"
    if not readme.is_file():
        return []
    matches = list(RUN_LINE.finditer(run_lines(readme.read_text(errors="replace"))))
    wanted = script.relative_to(root).as_posix()
    same = [m for m in matches if m.group(1) == wanted]
    if not same:  # a README naming its script under another folder (nocs: examples/datasets/nocs/main.py)
        same = [m for m in matches if Path(m.group(1)).parent.name == script.parent.name
                and Path(m.group(1)).name == script.name]
    found = [[arg for arg in shlex.split(PLACEHOLDER.sub(_one_word, m.group(2).split("#")[0])) if arg != "\\"]
             for m in same]
    return max(found, key=len, default=[])


def _one_word(match: re.Match) -> str:
    """A README placeholder (``<path to cam_pose file>``) as one argument: ``<path_to_cam_pose_file>``."""
    return "<" + "_".join(match.group(1).split()) + ">"


def resolve_placeholder(arg: str, work: Path) -> str:
    """A README placeholder's stand-in: a number for ``<number of ...>``, the camera file for a camera pose
    file, else the name it asks for (``<path_to_house.json>`` -> ``house.json``) resolved as any argument."""
    inner = arg[1:-1].lower()
    if "number" in inner:
        return "2560"
    if "cam" in inner:
        return str(work / "camera_positions")
    return re.sub(r"^path_to_(the_)?", "", arg[1:-1], flags=re.IGNORECASE)


def resolve_arg(arg: str, root: Path, work: Path, output: Path) -> str:
    """The checkout's file, a temporary output folder, or a stand-in (see the module documentation)."""
    mapped = dataset_arg(arg, work)  # a dataset the README names (tools/bproc_dataset_standins.py)
    if mapped is not None:
        return mapped
    if arg.startswith("<") and arg.endswith(">"):
        arg = resolve_placeholder(arg, work)
    if arg.startswith("-") or re.fullmatch(r"[-+]?\d+(\.\d+)?", arg):
        return arg
    if "output" in arg:
        return str(output / Path(arg).name)
    if (root / arg).exists():
        return arg
    name = Path(arg).name
    if name.endswith(".ply"):
        return str(work / "bop" / "lm" / "models" / "obj_000001.ply")
    for candidate in (work / name, work / "scene.obj" if name.endswith(".obj") else None,
                      work / "bop" if "bop" in arg.lower() else None, work / "cc_textures" if "cc" in name else None):
        if candidate is not None and candidate.exists():
            return str(candidate)
    return arg


def run_one(script: Path, root: Path, work: Path, timeout: float, max_samples: int | None) -> tuple[str, str, float]:
    """(``runs``/``fails``, detail, seconds) of one example."""
    with tempfile.TemporaryDirectory(prefix="out-", dir=work) as output:
        args = [resolve_arg(a, root, work, Path(output)) for a in readme_args(script, root)]
        env = dict(os.environ)
        if max_samples:
            env["HYBRIDGEN_BPROC_MAX_SAMPLES"] = str(max_samples)
        command = [sys.executable, "-m", "hybridgen", "-q", "run", str(script.relative_to(root)), *args]
        started = time.perf_counter()
        try:
            done = subprocess.run(command, cwd=root, env=env, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return "fails", f"timeout after {timeout:.0f} s", time.perf_counter() - started
        seconds = time.perf_counter() - started
        if done.returncode == 0:
            return "runs", "", seconds
        lines = [line for line in (done.stderr + done.stdout).splitlines() if line.strip()]
        return "fails", (lines[-1] if lines else f"exit status {done.returncode}")[:240], seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("path", type=Path, help="BlenderProc working tree or bare git mirror")
    parser.add_argument("--tag", default=None, help="tag to read from a bare mirror (e.g. v.2.8.0)")
    parser.add_argument("--only", default="", help="run only examples whose path contains this")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per example (default 600)")
    parser.add_argument("--max-samples", type=int, default=None, help="cap color samples per pixel")
    ns = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bproc-scripts-") as temp:
        root = Path(temp) / "checkout"
        if ns.tag is None:
            root = ns.path
        else:
            example_configs(ns.path, ns.tag, root)
        work = Path(temp) / "standins"
        work.mkdir()
        make_standins(work)
        from PIL import Image

        (work / "images").mkdir()
        for index, color in enumerate(((200, 60, 60), (60, 160, 90))):  # material_manipulation's textures
            Image.new("RGB", (16, 16), color).save(work / "images" / f"material_manipulation_sample_texture{index}.jpg")
        scripts = sorted(p for p in (root / "examples").rglob("main.py") if ns.only in str(p))
        copy_resources(ns.path, ns.tag, root)
        make_dataset_standins(work, "\n".join(p.read_text(errors="replace") for p in scripts), root)
        counts = {"runs": 0, "fails": 0}
        for script in scripts:
            status, detail, seconds = run_one(script, root, work, ns.timeout, ns.max_samples)
            counts[status] += 1
            name = str(script.parent.relative_to(root / "examples"))
            print(f"{name:48s} {status}{': ' + detail if detail else ''} ({seconds:.1f} s)", flush=True)
        print(f"{len(scripts)} example scripts: {counts['runs']} run, {counts['fails']} fail")


if __name__ == "__main__":
    main()
