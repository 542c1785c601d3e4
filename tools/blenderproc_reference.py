"""The real BlenderProc, run on pip's ``bpy`` beside hybridgen: set up once, then an example script per call.

    .venv/bin/python tools/blenderproc_reference.py setup
    .venv/bin/python tools/blenderproc_reference.py run examples/basics/basic/main.py \\
        examples/resources/camera_positions examples/resources/scene.obj OUT

BlenderProc's main branch renders here without a Blender download (``../shared/FACTS.md``, "Peers"): a venv of its
own (``.venv-blenderproc``, git-ignored: Python 3.11, ``bpy==4.2.0``, ``numpy<2`` and the pinned pip list of
BlenderProc's ``DefaultConfig.default_pip_packages``, read from the mirror at setup time), the ``blenderproc/``
package of the mirror's ``HEAD`` extracted into a cache folder (never into this repository: BlenderProc is
GPL-3.0) and put on ``PYTHONPATH``, and ``USE_EXTERNAL_BPY_MODULE=1``. An example runs as
``python examples/.../main.py ARGS`` from an extracted checkout of the mirror's examples (tag ``v.2.8.0`` by
default), the same files ``hybridgen run`` is given.

Where: the mirror is ``$BLENDERPROC_MIRROR`` or ``/work/.mirror/DLR-RM+BlenderProc/repo`` (a bare git directory);
extracted trees go under ``$HYBRIDGEN_BLENDERPROC_CACHE`` or ``~/.cache/hybridgen/blenderproc``, one folder per
commit. Setup is idempotent: the venv is reused while a marker file in it names the same package list. Only PyPI
is contacted (pip). Without the venv, ``run`` stops with one line saying how to make it.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
VENV = REPO / ".venv-blenderproc"
MIRROR = Path(os.environ.get("BLENDERPROC_MIRROR", "/work/.mirror/DLR-RM+BlenderProc/repo"))
CACHE = Path(os.environ.get("HYBRIDGEN_BLENDERPROC_CACHE", "~/.cache/hybridgen/blenderproc")).expanduser()
EXAMPLES_TAG = "v.2.8.0"
SOURCE_REV = "HEAD"
BASE_PACKAGES = ("bpy==4.2.0", "numpy<2")
"""BlenderProc checks for Blender 4.2 exactly; bpy 4.2's own modules need NumPy 1."""
MARKER = "hybridgen-blenderproc-packages.txt"
SETUP_HINT = "run `.venv/bin/python tools/blenderproc_reference.py setup` (needs Python 3.11 and PyPI)"


class ReferenceUnavailable(RuntimeError):
    """The real BlenderProc cannot run here; the message is one line saying why and what to do."""


# ------------------------------------------------------------------------------------------- the mirror
def _git(*args: str) -> bytes:
    done = subprocess.run(["git", "-C", str(MIRROR), *args], capture_output=True, check=False)
    if done.returncode != 0:
        raise ReferenceUnavailable(f"BlenderProc mirror {MIRROR}: git {' '.join(args)} failed: "
                                   f"{done.stderr.decode(errors='replace').strip().splitlines()[-1:]}")
    return done.stdout


def commit_of(rev: str) -> str:
    """The full commit id ``rev`` names in the mirror."""
    return _git("rev-parse", f"{rev}^{{commit}}").decode().strip()


def _write_tree(rev: str, paths: tuple[str, ...], into: Path) -> list[str]:
    """The files under ``paths`` at ``rev`` written below ``into`` (one ``git cat-file --batch``); returns the
    paths whose blobs the mirror lacks (large files it did not fetch), which are skipped."""
    listing = _git("ls-tree", "-r", rev, "--", *paths).decode().splitlines()
    entries = [(line.split()[2], line.split("\t", 1)[1], line.split()[0]) for line in listing
               if line.split()[1] == "blob"]
    done = subprocess.run(["git", "-C", str(MIRROR), "cat-file", "--batch"], capture_output=True, check=True,
                          input="".join(f"{sha}\n" for sha, _, _ in entries).encode())
    stream, offset, missing = done.stdout, 0, []
    for sha, name, mode in entries:
        end = stream.index(b"\n", offset)
        header = stream[offset:end].decode().split()
        offset = end + 1
        if header[-1] == "missing":
            missing.append(name)
            continue
        size = int(header[2])
        target = into / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(stream[offset:offset + size])
        if mode == "100755":
            target.chmod(0o755)
        offset += size + 1
    return missing


def extract(rev: str, paths: tuple[str, ...], kind: str) -> Path:
    """``paths`` of the mirror at ``rev`` extracted once into ``CACHE/<kind>-<commit[:12]>`` (its path returned;
    files the mirror lacks are listed in its ``MISSING.txt``). Written under a temporary name and renamed, so
    concurrent callers never see half a tree."""
    target = CACHE / f"{kind}-{commit_of(rev)[:12]}"
    if target.is_dir():
        return target
    CACHE.mkdir(parents=True, exist_ok=True)
    partial = Path(tempfile.mkdtemp(prefix=f".{kind}-", dir=CACHE))
    missing = _write_tree(rev, paths, partial)
    (partial / "MISSING.txt").write_text("".join(f"{name}\n" for name in missing))
    try:
        partial.rename(target)
    except OSError:  # another process got there first
        shutil.rmtree(partial, ignore_errors=True)
    return target


def source_tree(rev: str = SOURCE_REV) -> Path:
    """A folder holding BlenderProc's ``blenderproc/`` package at ``rev`` (the one to put on PYTHONPATH)."""
    return extract(rev, ("blenderproc",), "source")


def examples_tree(tag: str = EXAMPLES_TAG) -> Path:
    """A folder holding BlenderProc's ``examples/`` at ``tag``: the root both engines run a script from."""
    return extract(tag, ("examples",), "examples")


def pinned_packages(rev: str = SOURCE_REV) -> list[str]:
    """BlenderProc's ``DefaultConfig.default_pip_packages`` at ``rev`` (the versions its own setup installs into
    Blender's Python), read from the mirror's source text."""
    text = _git("show", f"{rev}:blenderproc/python/utility/DefaultConfig.py").decode()
    block = re.search(r"default_pip_packages\s*=\s*\[(.*?)\]", text, re.S)
    if block is None:
        raise ReferenceUnavailable("BlenderProc's DefaultConfig.py has no default_pip_packages list")
    return re.findall(r"[\"']([^\"']+)[\"']", block.group(1))


# --------------------------------------------------------------------------------------------- the venv
def venv_python(venv: Path = VENV) -> Path:
    return venv / "bin" / "python"


def setup(venv: Path = VENV, rev: str = SOURCE_REV, quiet: bool = False) -> Path:
    """Makes (or finds) the venv with bpy and BlenderProc's pip list; returns its Python. Idempotent."""
    packages = [*BASE_PACKAGES, *pinned_packages(rev)]
    python = venv_python(venv)
    marker = venv / MARKER
    if python.exists() and marker.is_file() and marker.read_text().split() == packages:
        return python
    interpreter = shutil.which("python3.11")
    if interpreter is None:
        raise ReferenceUnavailable("BlenderProc reference: no python3.11 on PATH (pip's bpy 4.2 needs Python 3.11)")
    if not quiet:
        print(f"BlenderProc reference: installing {len(packages)} packages into {venv} (one-off, about 2 GB) ...",
              flush=True)
    steps = [[interpreter, "-m", "venv", str(venv)],
             [str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", *packages]]
    for step in steps:
        done = subprocess.run(step, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            tail = (done.stderr or done.stdout).strip().splitlines()[-1:]
            raise ReferenceUnavailable(f"BlenderProc reference: `{' '.join(step[:4])} ...` failed: {tail}")
    marker.write_text("\n".join(packages) + "\n")
    return python


def check_ready(venv: Path = VENV) -> Path:
    """The venv's Python when it can import bpy 4.2; else ReferenceUnavailable with one line."""
    python = venv_python(venv)
    if not python.exists():
        raise ReferenceUnavailable(f"BlenderProc reference: {venv} does not exist: {SETUP_HINT}")
    probe = subprocess.run([str(python), "-c", "import importlib.metadata as m; print(m.version('bpy'))"],
                           capture_output=True, text=True, check=False)
    if probe.returncode != 0:
        raise ReferenceUnavailable(f"BlenderProc reference: {venv} has no bpy: {SETUP_HINT}")
    if not probe.stdout.strip().startswith("4.2"):
        raise ReferenceUnavailable(f"BlenderProc reference: {venv} has bpy {probe.stdout.strip()}, BlenderProc "
                                   f"needs 4.2: {SETUP_HINT}")
    return python


# --------------------------------------------------------------------------------------------- running
@dataclass(frozen=True)
class Invocation:
    """One example script run: the command, its working directory (the examples root) and environment."""

    command: list[str]
    cwd: Path
    env: dict[str, str]


LAUNCHER = REPO / "tools" / "bproc_launch.py"


def reference_invocation(script: str, args: list[str], launch: list[str] | None = None, root: Path | None = None,
                         extra_env: dict[str, str] | None = None) -> Invocation:
    """How the real BlenderProc runs ``script`` (relative to ``root``, default the extracted examples) with
    ``args``: the venv's Python on the script, BlenderProc's source on PYTHONPATH, USE_EXTERNAL_BPY_MODULE=1.
    ``launch``: options of tools/bproc_launch.py (render overrides, scene dump), which then runs the script."""
    python = check_ready()
    env = {key: value for key, value in os.environ.items() if key not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env.update(PYTHONPATH=str(source_tree()), USE_EXTERNAL_BPY_MODULE="1", **(extra_env or {}))
    prefix = [str(python)] if launch is None else [str(python), str(LAUNCHER), "blenderproc", *launch]
    return Invocation([*prefix, script, *args], root or examples_tree(), env)


def hybridgen_invocation(script: str, args: list[str], launch: list[str] | None = None, root: Path | None = None,
                         extra_env: dict[str, str] | None = None, tree: Path | None = None) -> Invocation:
    """How hybridgen runs the same script: ``hybridgen run script args`` with this checkout's Python (or, with
    ``launch``, tools/bproc_launch.py with those options). ``tree``: another source tree of hybridgen (a clone at
    a commit) put first on PYTHONPATH, ahead of the checkout the venv has installed."""
    env = {**os.environ, **(extra_env or {})}
    if tree is not None:
        env["PYTHONPATH"] = str(tree)
    prefix = ([sys.executable, "-m", "hybridgen", "-q", "run"] if launch is None
              else [sys.executable, str(LAUNCHER), "hybridgen", *launch])
    return Invocation([*prefix, script, *args], root or examples_tree(), env)


def execute(invocation: Invocation, log: Path | None = None, timeout: float | None = None) -> int:
    """Runs an invocation to its end (output to ``log`` or inherited); its exit status."""
    with open(log, "w") if log else open(os.devnull, "w") as sink:
        stream = sink if log else None
        done = subprocess.run(invocation.command, cwd=invocation.cwd, env=invocation.env, stdout=stream,
                              stderr=subprocess.STDOUT if log else None, timeout=timeout, check=False)
    return done.returncode


def script_path(example: str) -> str:
    """``basics/basic`` (or ``examples/basics/basic`` or the script's path) -> ``examples/basics/basic/main.py``."""
    name = example.removeprefix("examples/").removesuffix("/main.py").strip("/")
    return f"examples/{name}/main.py"


def example_args(script: str, root: Path, output: Path, work: Path) -> list[str]:
    """The arguments of the example README's ``blenderproc run`` line (tools/check_blenderproc_scripts.py), with the
    output folder replaced by ``output`` and material_manipulation's ``images`` folder made under ``work`` (the
    example's own texture under the name its script looks for)."""
    sys.path.insert(0, str(REPO / "tools"))
    from check_blenderproc_scripts import readme_args, resolve_arg

    texture = root / Path(script).parent / "sample_texture.jpg"
    if texture.is_file():
        (work / "images").mkdir(parents=True, exist_ok=True)
        shutil.copyfile(texture, work / "images" / "material_manipulation_sample_texture0.jpg")
    return [str(output) if "output" in arg and not arg.startswith("-") else resolve_arg(arg, root, work, output)
            for arg in readme_args(root / script, root)]


def key_of(*parts: str) -> str:
    """A short digest of text parts (a script's content and its args): a cache key."""
    return hashlib.sha256("\x00".join(parts).encode()).hexdigest()[:16]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("setup", help="make .venv-blenderproc and extract BlenderProc's source and examples")
    run = sub.add_parser("run", help="run an example with the real BlenderProc, from the examples root (give the "
                                     "output folder as an absolute path)")
    run.add_argument("example", help="basics/basic, examples/basics/basic or its main.py")
    run.add_argument("args", nargs=argparse.REMAINDER, help="the script's arguments (default: its README's, the "
                                                            "output folder ./<example name>-blenderproc)")
    ns = parser.parse_args()
    try:
        if ns.command == "setup":
            python = setup()
            check_ready()
            print(f"BlenderProc reference ready: {python}; source {source_tree()}; examples {examples_tree()}")
            return
        script = script_path(ns.example)
        args = ns.args
        if not args:
            output = Path.cwd() / f"{Path(script).parent.name}-blenderproc"
            args = example_args(script, examples_tree(), output, output.with_name(output.name + "-inputs"))
        invocation = reference_invocation(script, args)
        print("BlenderProc reference:", " ".join(invocation.command[1:]), flush=True)
    except ReferenceUnavailable as exc:
        raise SystemExit(str(exc)) from None
    raise SystemExit(execute(invocation))


if __name__ == "__main__":
    main()
