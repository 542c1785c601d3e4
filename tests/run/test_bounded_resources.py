"""Resources stay bounded: memory over many scenes, units generated lazily, YAML bombs, oversized inputs,
and --workers / Ray address checks."""
from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.run.scene_configs import LABELS_WITHOUT_NORMALS, floor_and_object

SCENES = floor_and_object(initializer="seed: 3, number_of_scenes: SCENES", width=8, height=6, keypoints=1,
                          renderer=LABELS_WITHOUT_NORMALS)
PEAK_RSS = ("import resource, sys; from hybridgen.cli import main; rc = main(sys.argv[1:]); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(rc)")


def _peak_rss_mib(*argv: str) -> float:
    result = subprocess.run([sys.executable, "-c", PEAK_RSS, *argv], cwd=REPO, capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    return int(result.stdout.split()[-1]) / 1024


def _rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS")


def test_memory_does_not_grow_with_the_number_of_scenes(gl_context, tmp_path, write_config):
    """Ten times the scenes, the same peak (it grew ~1.7 MB per scene before: GL programs, open shards;
    measured 0.4-1.6 MB apart now)."""
    few = _peak_rss_mib("run", "-q", str(write_config(SCENES.replace("SCENES", "6"), "few.yaml")),
                        str(tmp_path / "few"))
    many = _peak_rss_mib("run", "-q", str(write_config(SCENES.replace("SCENES", "60"), "many.yaml")),
                         str(tmp_path / "many"))
    assert many - few < 5, (few, many)


INDEX_PEAK = """
import shutil, sys
from pathlib import Path
from hybridgen.run.shard_index import build_index
shard, folder, count = Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3])
(folder / "shards").mkdir(parents=True)
shards = [folder / "shards" / f"scene_{i:06d}_chunk_00000.hdf5" for i in range(count)]
for path in shards:
    shutil.copyfile(shard, path)
def peak_kib():
    return int(next(line for line in open("/proc/self/status") if line.startswith("VmHWM")).split()[1])
with open("/proc/self/clear_refs", "w") as refs:
    refs.write("5")  # the peak so far (imports) becomes the current RSS
before = peak_kib()
build_index(folder / "data.hdf5", shards)
print(peak_kib() - before)
"""


def test_index_memory_per_shard_is_small(gl_context, tmp_path, write_config, run_cli):
    """Building data.hdf5 over N shards: HDF5 keeps every virtual dataset's decoded mapping (~4 KB per shard
    and dataset) while its header is cached, and the seal held every dataset open at once - ~130 KB per
    shard (18 MB of the 12-vs-120-scene difference). With a small fixed metadata cache and datasets sealed
    one at a time it is ~20 KB per shard, freed when the file closes."""
    code, _, err = run_cli("run", "-q", str(write_config(SCENES.replace("SCENES", "1"))), str(tmp_path / "out"),
                           "--workers", "2")
    assert code == 0, err
    shard = tmp_path / "out/shards/scene_000000_chunk_00000.hdf5"
    growth = {}
    for count in (50, 450):
        result = subprocess.run([sys.executable, "-c", INDEX_PEAK, str(shard), str(tmp_path / f"index{count}"),
                                 str(count)], cwd=REPO, capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-2000:]
        growth[count] = int(result.stdout.split()[-1])  # KiB
    per_shard = (growth[450] - growth[50]) / 400
    assert per_shard < 50, growth  # KiB; ~26 now, ~100 before


def test_units_are_generated_lazily(gl_context, tmp_path, write_config):
    """number_of_scenes: 20000000 - the parent's memory stays flat while it works (it grew ~32 MB/s when
    every unit was queued up front); SIGTERM then ends it."""
    config = write_config(SCENES.replace("SCENES", "20000000"))
    process = subprocess.Popen([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(tmp_path / "out")],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(list((tmp_path / "out/shards").glob("*.hdf5"))) < 3:
            time.sleep(0.2)
        early = _rss_mib(process.pid)
        time.sleep(4)
        late = _rss_mib(process.pid)
        assert process.poll() is None and late - early < 10, (early, late)
    finally:
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=60) == 143


def _bounded_cli(*argv: str) -> tuple[int, str, float, float]:
    """(exit status, stderr, seconds, peak RSS MiB) of a CLI call in a fresh process."""
    start = time.monotonic()
    result = subprocess.run([sys.executable, "-c", PEAK_RSS, *argv], cwd=REPO, capture_output=True, text=True,
                            timeout=120)
    seconds = time.monotonic() - start
    rss = int(result.stdout.split()[-1]) / 1024 if result.stdout.strip() else 0.0
    return result.returncode, result.stderr, seconds, rss


@pytest.mark.parametrize("case", ["60_yaml_alias_bomb", "61_yaml_deep_nesting", "64_recursive_alias"])
def test_yaml_bombs_are_bounded_in_time_and_memory(tmp_path, case):
    baseline = _bounded_cli("modules", "main.Initializer")[3]  # imports the same code, parses nothing
    code, err, seconds, rss = _bounded_cli("run", "-q", str(REPO / f"tests/bad_inputs/{case}.yaml"),
                                           str(tmp_path / "out"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert seconds < 30 and rss - baseline < 200, (seconds, rss, baseline)


def test_endless_or_huge_inputs_are_one_line(gl_context, tmp_path, write_config, run_cli):
    code, _, err = run_cli("run", "-q", "/dev/zero", str(tmp_path / "out"))
    assert code == 2 and "larger than 16 MiB" in err and len(err.strip().splitlines()) == 1
    poses = SCENES.replace("SCENES", "1").replace(
        "  - name: camera.CameraSampler", "  - name: camera.CameraLoader\n    config: {path: /dev/zero, "
        "file_format: location rotation/value, intrinsics: {resolution_x: 8, resolution_y: 6}}\n"
        "  - name: camera.CameraSampler")
    code, _, err = run_cli("run", "-q", str(write_config(poses)), str(tmp_path / "out"))
    assert code == 2 and "camera pose file '/dev/zero' is larger than" in err


def test_latin1_label_csv_is_read(tmp_path):
    from hybridgen.io.coco_writer import load_label_mapping

    table = tmp_path / "labels.csv"
    table.write_bytes("id,name\n1,caf\xe9\n2,r\xe9gion\n".encode("latin-1"))
    assert load_label_mapping(table) == {1: "café", 2: "région"}


@pytest.mark.parametrize("workers", ["0", "-1"])
def test_workers_below_one_are_refused_everywhere(gl_context, tmp_path, write_config, run_cli, workers):
    config = write_config(SCENES.replace("number_of_scenes: SCENES", "number_of_scenes: 1"))
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"), "--workers", workers)
    assert code == 2 and "--workers must be an integer >= 1" in err
    assert not (tmp_path / "out").exists()


def test_unreachable_ray_address_is_one_line_not_a_hang(gl_context, tmp_path, write_config, run_cli):
    pytest.importorskip("ray")
    config = write_config(SCENES.replace("SCENES", "2"))
    start = time.monotonic()
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"), "--executor", "ray",
                           "--address", "127.0.0.1:1")
    assert code == 2 and "cannot reach the Ray cluster at 127.0.0.1:1" in err
    assert time.monotonic() - start < 60 and len(err.strip().splitlines()) == 1


def test_worker_processes_are_recycled(gl_context, tmp_path, write_config):
    """--max-tasks-per-child 1: every unit gets a fresh worker process; the result is the same bytes."""
    from tests.run.test_locking_signals import _descendants

    config = write_config(SCENES.replace("SCENES", "4"))
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(out), "--workers",
                                "2", "--max-tasks-per-child", "1"], cwd=REPO, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    seen: set[int] = set()
    while process.poll() is None:
        seen |= _descendants(process.pid)
        time.sleep(0.05)
    assert process.returncode == 0, process.stderr.read()
    assert len(seen) >= 5, seen  # 4 units -> 4 workers, plus multiprocessing's resource tracker
    assert len(list((out / "shards").glob("*.hdf5"))) == 4
