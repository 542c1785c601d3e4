"""Modules' status lines reach the user from every kind of unit: a staged run in this process and the pool
workers of ``--workers 2`` log like the command line that started them (same format, same level)."""
from __future__ import annotations

import subprocess
import sys

from tests.conftest import REPO
from tests.run.scene_configs import LABELS_WITHOUT_NORMALS, floor_and_object

LINE = "hybridgen: manipulators.EntityManipulator: selector matches no object; nothing to do"
MANIPULATOR = """  - name: manipulators.EntityManipulator
    config: {selector: {provider: getter.Entity, conditions: {name: nothing}, check_empty: false}, scale: 2}
"""


def _config(write_config, initializer: str):
    text = floor_and_object(initializer=initializer, width=16, height=12, keypoints=2, renderer=LABELS_WITHOUT_NORMALS)
    return write_config(text.replace("  - name: writer.Hdf5Writer", MANIPULATOR + "  - name: writer.Hdf5Writer"))


def test_a_staged_run_in_this_process_logs_module_lines(gl_context, tmp_path, write_config, run_cli):
    config = _config(write_config, "seed: 2")
    code, _, err = run_cli("run", str(config), str(tmp_path / "out"))
    assert code == 0 and err.count(LINE) == 1, err
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "again"))
    assert code == 0 and LINE not in err, err  # information: hidden by -q


def test_pool_workers_log_like_the_command_line(gl_context, tmp_path, write_config):
    config = _config(write_config, "seed: 2, number_of_scenes: 2")
    done = subprocess.run([sys.executable, "-m", "hybridgen", "run", str(config), str(tmp_path / "out"), "--workers",
                           "2"], cwd=REPO, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count(LINE + "\n") == 2, done.stderr  # one per scene, each from a worker, formatted
