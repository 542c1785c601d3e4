"""How `hybridgen run script.py ARGS` runs a BlenderProc 2 script: `import blenderproc` is hybridgen's even with the
real package installed, sys.argv and the working directory are the script's, BLENDER_PROC_RANDOM_SEED seeds
random and np.random as BlenderProc does, the script's own error is its traceback with status 1 and hybridgen's
errors are one line with status 2. Nothing here renders."""
from __future__ import annotations

import importlib.util
import json
import random
import sys
from pathlib import Path

import numpy as np
import pytest

PROBE = """
import json, os, random, sys
import numpy as np
import blenderproc as bproc
import blenderproc.camera
import bpy
bproc.init()
out = {"module": bproc.__name__, "camera": blenderproc.camera.__name__, "argv": sys.argv, "cwd": os.getcwd(),
       "np": float(np.random.rand()), "py": random.random(), "bpy_clip": bpy.context.scene.camera.data.clip_end,
       "frames": bproc.utility.num_frames()}
with open(sys.argv[1], "w") as f:
    json.dump(out, f)
"""


def _run(run_cli, tmp_path: Path, text: str, *args: str) -> tuple[int, str, str]:
    script = tmp_path / "main.py"
    script.write_text(text)
    return run_cli("run", str(script), *args)


def test_blenderproc_is_hybridgens_and_argv_is_the_scripts(run_cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(run_cli, tmp_path, PROBE, "probe.json", "--flag", "7")
    assert code == 0, err
    probe = json.loads((tmp_path / "probe.json").read_text())
    assert probe["module"] == "hybridgen.bproc" and probe["camera"] == "hybridgen.bproc.camera"
    assert probe["argv"] == [str(tmp_path / "main.py"), "probe.json", "--flag", "7"]  # options go to the script
    assert probe["cwd"] == str(tmp_path) and probe["bpy_clip"] == 1000.0 and probe["frames"] == 0
    assert "blenderproc" not in sys.modules or not sys.modules["blenderproc"].__name__.startswith("hybridgen")


@pytest.mark.skipif(importlib.util.find_spec("blenderproc") is None, reason="the real blenderproc is not installed")
def test_the_real_blenderproc_imported_before_is_not_the_scripts(run_cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("OUTSIDE_OF_THE_INTERNAL_BLENDER_PYTHON_ENVIRONMENT_BUT_IN_RUN_SCRIPT", "1")
    import blenderproc as real  # its __init__ without Blender: no API, but the package is in sys.modules

    code, _, err = _run(run_cli, tmp_path, PROBE, "probe.json")
    assert code == 0, err
    assert json.loads((tmp_path / "probe.json").read_text())["module"] == "hybridgen.bproc"
    assert sys.modules["blenderproc"] is real  # restored after the run


def test_blender_proc_random_seed_seeds_as_blenderproc(run_cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("BLENDER_PROC_RANDOM_SEED", "5")
    draws = []
    for name in ("a.json", "b.json"):
        assert _run(run_cli, tmp_path, PROBE, name)[0] == 0
        draws.append(json.loads((tmp_path / name).read_text()))
    np.random.seed(5)
    random.seed(5)
    expected = (float(np.random.rand()), random.random())
    assert [(d["np"], d["py"]) for d in draws] == [expected, expected]
    monkeypatch.setenv("BLENDER_PROC_RANDOM_SEED", "6")
    assert _run(run_cli, tmp_path, PROBE, "c.json")[0] == 0
    assert json.loads((tmp_path / "c.json").read_text())["np"] != expected[0]


def test_a_script_error_shows_its_traceback_and_exits_1(run_cli, tmp_path: Path) -> None:
    text = "import blenderproc as bproc\nbproc.init()\n\ndef place():\n    raise ValueError('no floor here')\n\nplace()\n"
    code, _, err = _run(run_cli, tmp_path, text)
    assert code == 1
    assert "Traceback (most recent call last)" in err and "ValueError: no floor here" in err
    assert f'File "{tmp_path / "main.py"}", line 7' in err and "runpy" not in err


@pytest.mark.parametrize("call, line", [
    ("bproc.renderer.enable_motion_blur(0.5)",
     "bproc.renderer.enable_motion_blur is not supported by hybridgen yet"),
    ("bproc.loader.load_obj('missing.obj')", "The given filepath does not exist: missing.obj"),
    ("bproc.renderer.render()", "No camera poses have been registered"),
    ("import bpy; bpy.ops.mesh.primitive_cube_add()", "bpy.ops is not supported by hybridgen yet"),
])
def test_hybridgens_errors_are_one_line_with_status_2(run_cli, tmp_path: Path, monkeypatch, call: str,
                                                      line: str) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(run_cli, tmp_path, f"import blenderproc as bproc\nbproc.init()\n{call}\n")
    assert code == 2
    assert line in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err


def test_a_missing_script_is_one_line(run_cli, tmp_path: Path) -> None:
    code, _, err = run_cli("run", str(tmp_path / "nope.py"))
    assert code == 2 and "nope.py' does not exist" in err and "Traceback" not in err
