"""tools/reference_cache.py: the quality benchmark's references are found again exactly when what defines them
is unchanged (code without docstrings, scene content, settings), and never read half-written."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tools.reference_cache import (ReferenceCache, cache_root, code_digest, estimator_digest, module_closure,
                                   scene_digest)

REPO = Path(__file__).resolve().parents[2]


def _digests(sources: dict[str, str], folder: Path) -> dict[str, str]:
    """:func:`code_digest` of each named source, written to ``folder/<name>.py``."""
    for name, text in sources.items():
        (folder / f"{name}.py").write_text(text)
    return {name: code_digest(folder / f"{name}.py") for name in sources}


def test_code_digest_ignores_docstrings_and_comments_not_code(tmp_path: Path) -> None:
    base = 'def f(x):\n    """Doubles."""\n    return 2 * x\n'
    variants = {
        "same": base,
        "docs": 'def f(x):\n    """Twice x, in other words."""\n    # a comment\n    return 2 * x  # trailing\n',
        "nodoc": "def f(x):\n    return 2 * x\n",
        "code": 'def f(x):\n    """Doubles."""\n    return 3 * x\n',
    }
    digests = _digests(variants, tmp_path)
    assert digests["same"] == digests["docs"] == digests["nodoc"]
    assert digests["code"] != digests["same"]


def test_code_digest_ignores_attribute_docstrings_not_constants(tmp_path: Path) -> None:
    """A string under a constant documents it (Sphinx's attribute docstrings, as hybridgen writes them); editing
    it must not re-render references, while the constant's value must."""
    variants = {
        "base": 'LIMIT = 4\n"""At most four."""\n\nclass C:\n    size: int = 2\n    """Pixels."""\n',
        "reworded": 'LIMIT = 4\n"""No more than four, measured."""\n\nclass C:\n    size: int = 2\n    """Pixels wide."""\n',
        "bare": "LIMIT = 4\n\nclass C:\n    size: int = 2\n",
        "value": 'LIMIT = 5\n"""At most four."""\n\nclass C:\n    size: int = 2\n    """Pixels."""\n',
        "field": 'LIMIT = 4\n"""At most four."""\n\nclass C:\n    size: int = 3\n    """Pixels."""\n',
    }
    digests = _digests(variants, tmp_path)
    assert digests["base"] == digests["reworded"] == digests["bare"]
    assert len({digests["base"], digests["value"], digests["field"]}) == 3


def test_module_closure_follows_relative_lazy_and_parent_imports(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    (package / "sub").mkdir(parents=True)
    files = {
        "__init__.py": "",
        "a.py": "import os\nfrom . import b\n\ndef f():\n    from .sub.c import value\n    return value\n",
        "b.py": ("from typing import TYPE_CHECKING\nfrom pkg.sub import d\n"
                 "if TYPE_CHECKING:\n    from . import unused\n"),
        "unused.py": "from . import a\n",
        "sub/__init__.py": "",
        "sub/c.py": "from ..b import something\nvalue = 1\n",
        "sub/d.py": "",
    }
    for name, text in files.items():
        (package / name).write_text(text)
    found = module_closure(["pkg.a"], root=tmp_path, package="pkg")
    assert set(found) == {"pkg", "pkg.a", "pkg.b", "pkg.sub", "pkg.sub.c", "pkg.sub.d"}
    assert found["pkg.sub.c"] == package / "sub" / "c.py"


def test_estimator_closure_is_the_path_tracer_not_the_rasterizer() -> None:
    found = module_closure(["hybridgen.render.pathtrace.path_trace", "hybridgen.render.tonemap"])
    for needed in ("hybridgen.render.pathtrace.path_trace", "hybridgen.render.pathtrace.mitsuba_scene",
                   "hybridgen.render.pathtrace.adaptive_sampling", "hybridgen.render.tonemap", "hybridgen.scene.material"):
        assert needed in found
    assert "hybridgen.render.raster.raster_view" not in found and "hybridgen.io.hdf5_single" not in found
    assert estimator_digest() == estimator_digest()


def _export(folder: Path, vertices: np.ndarray, threads: int) -> Path:
    """A minimal export in cycles_export.export_for_cycles' layout, with an HDRI file in ``folder``."""
    folder.mkdir()
    (folder / "sky.exr").write_bytes(b"sky pixels")
    meta = {"objects": [{"name": "floor"}], "hdri": {"path": str(folder / "sky.exr"), "strength": 1.0},
            "threads": threads, "spp": 1024, "resolution": [4, 3]}
    np.savez(folder / "scene.npz", meta=np.array(json.dumps(meta)), v0=vertices)
    return folder / "scene.npz"


def test_scene_digest_is_content_not_paths_or_worker_settings(tmp_path: Path) -> None:
    vertices = np.arange(9, dtype=np.float32).reshape(3, 3)
    first = scene_digest(_export(tmp_path / "a", vertices, threads=2))
    assert scene_digest(_export(tmp_path / "b", vertices, threads=16)) == first  # other folder, other threads
    moved = vertices.copy()
    moved[0, 0] = 0.5
    assert scene_digest(_export(tmp_path / "c", moved, threads=2)) != first
    (tmp_path / "a" / "sky.exr").write_bytes(b"another sky")
    assert scene_digest(tmp_path / "a" / "scene.npz") != first


def test_cache_renders_once_per_key_and_writes_whole_files(tmp_path: Path) -> None:
    cache = ReferenceCache(tmp_path / "cache")
    calls: list[int] = []
    image = np.random.default_rng(3).integers(0, 256, (5, 7, 3), dtype=np.uint8)

    def render() -> tuple[np.ndarray, dict]:
        calls.append(1)
        return image, {"seconds": 1.5}

    key = {"scene": "tabletop", "resolution": "7x5", "spp": 64, "content": "abc"}
    made, record = cache.fetch("cycles", key, render)
    again, record_again = cache.fetch("cycles", key, render)
    assert len(calls) == 1 and not record["cached"] and record_again["cached"]
    assert np.array_equal(made, image) and np.array_equal(again, image)
    assert record_again["seconds"] == 1.5 and record_again["key"] == key
    cache.fetch("cycles", {**key, "content": "abd"}, render)
    cache.fetch("hybridgen", key, render)
    assert len(calls) == 3
    names = sorted(p.name for p in (tmp_path / "cache").iterdir())
    assert len(names) == 6 and all(n.endswith((".png", ".json")) and not n.startswith(".") for n in names)
    assert sum(n.startswith("cycles-tabletop-7x5-64spp-") for n in names) == 4


def test_disabled_cache_always_renders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HYBRIDGEN_BENCH_CACHE", "off")
    assert cache_root() is None
    assert cache_root(str(tmp_path)) == tmp_path
    monkeypatch.setenv("HYBRIDGEN_BENCH_CACHE", str(tmp_path / "elsewhere"))
    assert cache_root() == tmp_path / "elsewhere"
    cache = ReferenceCache(None)
    calls: list[int] = []
    for _ in range(2):
        cache.fetch("cycles", {"scene": "s", "resolution": "1x1", "spp": 1},
                    lambda: (calls.append(1), (np.zeros((1, 1, 3), np.uint8), {}))[1])
    assert len(calls) == 2


def test_whole_process_timing_counts_the_child_and_its_children() -> None:
    """harness.run_process (how the color quality benchmark times a process): CPU from the child's own rusage
    includes a grandchild's busy loop (a process that spawns helpers, as hybridgen's variant probe does), and the
    child's last JSON line is its report."""
    burn = "import time\nend = time.process_time() + 0.3\nwhile time.process_time() < end: pass\n"
    script = (f"import subprocess, sys\nsubprocess.run([sys.executable, '-c', {burn!r}], check=True)\n"
              "print('noise')\nprint('{\"done\": 1}')\n")
    code = ("import sys; sys.path.insert(0, 'tools'); import json, harness as q\n"
            f"r = q.run_process([sys.executable, '-c', {script!r}], dict(__import__('os').environ))\n"
            "print(json.dumps({'report': r.report, 'wall': r.wall, 'cpu': r.cpu}))")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["report"] == {"done": 1}
    assert 0.3 <= result["cpu"] <= result["wall"] * 2 + 0.1


def test_default_color_process_renders_what_render_color_renders(tmp_path: Path) -> None:
    """tools/default_color_process.py (the process the quality benchmark times) writes the same bytes as an
    in-process ``render_color`` with no color options (denoised), and reports its phases in order."""
    from PIL import Image

    import hybridgen as hg

    png = tmp_path / "materials.png"
    done = subprocess.run([sys.executable, str(REPO / "tools" / "default_color_process.py"), "materials", "40x30",
                           str(png), str(tmp_path)], cwd=REPO, capture_output=True, text=True, check=True)
    report = json.loads(done.stdout.strip().splitlines()[-1])
    marks = [report[key] for key in ("started", "imported", "built", "rendered", "written")]
    assert marks == sorted(marks) and report["mean_spp"] >= 1
    import color_quality  # tools/ is on sys.path (tests/tools/conftest.py)
    sink = hg.MemorySink()
    hg.render_color(color_quality.build("materials", 40, 30, tmp_path), [sink], hg.PathTraceSettings(), seed=1,
                    denoise=True, sample_counts=True)
    assert np.array_equal(np.asarray(Image.open(png).convert("RGB")), sink.frames[0]["colors"])
    assert report["mean_spp"] == pytest.approx(float(sink.frames[0]["sample_counts"].mean()))


def test_a_process_that_crashes_after_its_work_is_counted_only_when_told_so() -> None:
    """harness.run_process(crash_after=...): BlenderProc's bpy may segfault on its way out after writing every file
    (basics/material_manipulation); such a run counts, any other crash or failure still raises."""
    import harness

    done = ["bash", "-c", "echo Cleaning temporary directory; kill -SEGV $$"]
    finished = harness.run_process(done, crash_after="Cleaning temporary directory")
    assert finished.lines == ["Cleaning temporary directory"] and finished.wall > 0
    with pytest.raises(RuntimeError, match="exit -11"):
        harness.run_process(["bash", "-c", "echo halfway; kill -SEGV $$"], crash_after="Cleaning temporary directory")
    with pytest.raises(RuntimeError, match="exit -11"):
        harness.run_process(done)
    with pytest.raises(RuntimeError, match="exit 3"):
        harness.run_process(["bash", "-c", "echo Cleaning temporary directory; exit 3"],
                            crash_after="Cleaning temporary directory")
