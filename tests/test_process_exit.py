"""The command's fast exit (hybridgen/process_exit.py): a successful run ends without the interpreter's teardown,
after its files are committed, its atexit handlers ran and its output was flushed; errors exit normally."""
from __future__ import annotations

import json
import subprocess
import sys
import threading
from pathlib import Path

import h5py

from hybridgen.cli import main as cli_main
from hybridgen.process_exit import unfinished_work
from tests.conftest import REPO
from tests.run.scene_configs import floor_and_object

COLOR_RUN = floor_and_object(initializer="seed: 5", width=32, height=24, keypoints=2,
                             renderer="  - name: renderer.RgbRenderer\n    config: {samples: 4, render_depth: true}")

CHILD = """
import atexit, sys
from pathlib import Path
marks = Path(sys.argv[1])
atexit.register(lambda: (marks / "atexit").write_text("ran"))
class Teardown:  # a module global: deleted when the interpreter tears its modules down
    def __del__(self):
        (marks / "teardown").write_text("ran")
keeper = Teardown()
sys.argv = ["hybridgen", *sys.argv[2:]]
from hybridgen.cli import console_main
console_main()
"""


def command_line(marks: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    """The ``hybridgen`` command (console_main) in a child process, with an atexit handler and an object that
    only the interpreter's teardown deletes, each leaving a file in ``marks`` when it runs."""
    marks.mkdir()
    return subprocess.run([sys.executable, "-c", CHILD, str(marks), *argv], cwd=REPO, capture_output=True,
                          text=True, timeout=600)


def files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_successful_run_ends_without_teardown_and_writes_what_an_in_process_run_writes(gl_context, tmp_path):
    config = tmp_path / "color.yaml"
    config.write_text(COLOR_RUN)
    out = tmp_path / "out"
    done = command_line(tmp_path / "marks", "run", "-q", "--json", str(config), str(out))
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1])["status"] == "ok"  # flushed before the exit
    assert (tmp_path / "marks" / "atexit").read_text() == "ran"
    assert not (tmp_path / "marks" / "teardown").exists()  # the fast path was taken
    fast = files(out)
    assert "data.hdf5" in fast and not any(name.endswith(".incomplete") for name in fast)
    out.rename(tmp_path / "fast")
    assert cli_main(["run", "-q", str(config), str(out)]) == 0  # same path: the file names the output folder
    assert files(out) == fast


def test_a_failed_run_exits_through_the_interpreter(tmp_path):
    config = tmp_path / "bad.yaml"
    config.write_text(COLOR_RUN.replace("samples: 4", "samples: many"))
    done = command_line(tmp_path / "marks", "run", "-q", str(config), str(tmp_path / "out"))
    assert done.returncode == 2
    assert "samples" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert (tmp_path / "marks" / "atexit").read_text() == "ran"
    assert (tmp_path / "marks" / "teardown").read_text() == "ran"  # normal shutdown


def test_a_running_thread_or_an_open_hdf5_file_keeps_the_normal_exit(tmp_path):
    assert unfinished_work() is None
    release = threading.Event()
    worker = threading.Thread(target=release.wait, name="still-working")
    worker.start()
    try:
        assert "still-working" in (unfinished_work() or "")
    finally:
        release.set()
        worker.join()
    assert unfinished_work() is None
    with h5py.File(tmp_path / "open.hdf5", "w"):
        assert unfinished_work() == "an HDF5 file is still open"
    assert unfinished_work() is None
