"""Blender Cycles for the color benchmarks: the ``bpy`` venv (pip ``bpy`` needs Python 3.11), and
tools/cycles_render.py run in it as a worker process that renders one keypoint of an exported scene
(tools/cycles_export.py) per request and answers with its times (seconds) as JSON.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]


def ensure_bpy_venv(venv: Path) -> Path | None:
    """The Python of ``venv`` with bpy; creates the venv (python3 -m venv; pip install bpy 'numpy<2')."""
    python = venv / "bin" / "python"
    probe = [str(python), "-c", "import bpy"]
    if python.exists() and subprocess.run(probe, capture_output=True, check=False).returncode == 0:
        return python
    print(f"Cycles: creating {venv} with bpy and numpy<2 (one-off, about 1 GB) ...", flush=True)
    start = time.perf_counter()
    interpreter = "python3.11" if shutil.which("python3.11") else "python3"
    steps = [[interpreter, "-m", "venv", str(venv)],
             [str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", "bpy", "numpy<2"]]
    for step in steps:
        try:
            done = subprocess.run(step, capture_output=True, text=True, check=False)
        except OSError as exc:
            print(f"Cycles skipped: {' '.join(step[:3])} failed: {exc}")
            return None
        if done.returncode != 0:
            tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
            print(f"Cycles skipped: `{' '.join(step)}` failed (bpy from PyPI needs Python 3.11):", *tail, sep="\n  ")
            return None
    size = subprocess.run(["du", "-sm", str(venv)], capture_output=True, text=True, check=False).stdout.split()[0]
    print(f"  installed in {time.perf_counter() - start:.0f} s, {size} MiB on disk", flush=True)
    return python

def bpy_version(python: Path) -> str:
    """The ``bpy`` package version of the bpy venv's ``python`` (without importing Blender)."""
    done = subprocess.run([str(python), "-c", "import importlib.metadata as m; print(m.version('bpy'))"],
                          capture_output=True, text=True, check=True)
    return done.stdout.strip()


class CyclesWorker:
    """tools/cycles_render.py in the bpy venv, rendering one keypoint per request."""

    def __init__(self, python: Path, scene_path: Path) -> None:
        self.log = scene_path.with_suffix(".log")
        with open(self.log, "w") as log:  # Blender's own output
            self.process = subprocess.Popen([str(python), str(REPO / "tools" / "cycles_render.py"), str(scene_path)],
                                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, text=True,
                                            bufsize=1)
        self.hello = self._answer()
        self.peak_rss_mib: float | None = None

    def _answer(self) -> dict[str, Any]:
        assert self.process.stdout is not None
        line = self.process.stdout.readline()
        if not line:
            tail = self.log.read_text(errors="replace").strip().splitlines()[-5:]
            raise RuntimeError(f"the Cycles worker stopped (exit code {self.process.wait()}):\n  " + "\n  ".join(tail))
        return json.loads(line)

    def render(self, index: int, light_tree: bool, seed: int, save: Path | None = None,
               **extra: Any) -> dict[str, Any]:
        """``extra``: ``mode`` ("blenderproc" / "reference") and ``spp``, see tools/cycles_render.py."""
        assert self.process.stdin is not None
        request = {"index": index, "light_tree": light_tree, "seed": seed, "save": str(save) if save else None,
                   **extra}
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        return self._answer()

    def close(self) -> None:
        if self.process.poll() is None and self.process.stdin is not None:
            self.process.stdin.write(json.dumps({"quit": True}) + "\n")
            self.process.stdin.flush()
            try:
                self.peak_rss_mib = self._answer().get("peak_rss_mib")
            except (RuntimeError, ValueError):
                pass
            self.process.wait(timeout=60)



class CyclesSession:
    """A :class:`CyclesWorker` on one exported scene, started on first use (cached references need none)."""

    def __init__(self, python: Path, npz: Path) -> None:
        self.python, self.npz = python, npz
        self.worker: Any = None

    def render(self, seed: int, png: Path, **request: Any) -> dict[str, Any]:
        """Keypoint 0 rendered into ``png``; ``request``: ``mode``, ``spp`` (tools/cycles_render.py)."""
        if self.worker is None:
            self.worker = CyclesWorker(self.python, self.npz)
        return self.worker.render(0, False, seed, png, **request)

    def close(self) -> None:
        if self.worker is not None:
            self.worker.close()
