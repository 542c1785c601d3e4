"""The README's Python examples run as written: the API example renders color and labels, the h5py recipe
reads what it wrote. Extracted from README.md at test time, so the README cannot rot."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def python_blocks(section: str) -> list[str]:
    """The ```python blocks of the README section whose heading is ``section``."""
    text = (ROOT / "README.md").read_text()
    start = text.index(f"\n## {section}\n")
    end = text.find("\n## ", start + 1)
    return re.findall(r"```python\n(.*?)```", text[start:end if end > 0 else None], flags=re.S)


def run_python(code: str, cwd: Path) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


def test_python_api_example_and_h5py_recipe(tmp_path: Path) -> None:
    (tmp_path / "configs").symlink_to(ROOT / "configs")  # "run from the repository root"
    [api] = python_blocks("Python API")
    small = api.replace("from_fov(0.9, 320, 240)", "from_fov(0.9, 160, 120)").replace("samples=16", "samples=4")
    assert small.count("160, 120") == 1 and small.count("samples=4") == 2  # the README still reads as tested
    printed = run_python(small, tmp_path)
    # the example prints the color shape, the classes seen (background 0, floor 1, knot 3) and the nearest depth
    shape, classes, nearest = re.fullmatch(r"\((.*?)\) \[(.*?)\] (\S+)\n", printed).groups()
    assert shape == "2, 120, 160, 3"
    assert classes.split() == ["0", "1", "3"]
    assert 0.5 < float(nearest) < 3.5

    with h5py.File(tmp_path / "out" / "data.hdf5", "r") as f:
        colors, depth = f["colors"][()], f["depth"][()]
        assert colors.shape == (2, 120, 160, 3) and colors.dtype == np.uint8
        lit = colors[np.isfinite(depth)]
        assert lit.mean() > 20  # the sun lights the floor and the knot: not a black image
        assert np.isinf(depth).any() and np.isfinite(depth).any()

    recipe, reader = python_blocks("Reading the output")
    printed = run_python(reader.replace('"output/quickstart"', '"out"'), tmp_path)
    assert printed == "2 (120, 160)\n"
    recipe = recipe.replace("output/quickstart/data.hdf5", "out/data.hdf5")
    recipe += ("\nassert colors.shape == (120, 160, 3) and depth.dtype.name == 'float32'"
               "\nassert {v['name'] for v in visible} <= {'knot', 'floor'} and visible"
               "\nassert [o['name'] for o in objects] == ['knot', 'floor']"
               "\nassert K.shape == (3, 3) and cam2world.shape == (4, 4)\n")
    run_python(recipe, tmp_path)
