"""One writer per output folder, unpredictable temporary files, and clean stops on SIGTERM / SIGINT."""
from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import pytest

from hybridgen.errors import InputError
from hybridgen.io.atomic import confined_path, temporary_path
from hybridgen.io.integrity import verify
from tests.conftest import REPO
from tools.scene_yaml import shell_cameras

SCENES = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: main.Initializer
    config: {seed: 3, number_of_scenes: SCENES, keypoints_per_chunk: 2}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 6, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.6, name: ball, category_id: 2}
""" + shell_cameras(width=16, height=12, count=4) + """
  - name: renderer.SegMapRenderer
  - name: writer.Hdf5Writer
"""
APPEND = """
global: {all: {output_dir: "<args:0>"}}
modules:
  - name: loader.PrimitiveLoader
    config: {shape: sphere, size: 0.6, name: ball, category_id: 2}
""" + shell_cameras(width=8, height=6, count="COUNT", elevation=None) + """
  - name: renderer.SegMapRenderer
    config: {render_normals: false}
  - name: writer.Hdf5Writer
    config: {layout: blenderproc, append_to_existing_output: true}
"""
HOLD_LOCK = ("import sys, time; from hybridgen.io.output_lock import output_lock\n"
             "with output_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(60)\n")


def _cli(*argv: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "hybridgen", *argv], cwd=REPO, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _descendants(pid: int) -> set[int]:
    """Every live descendant of ``pid`` found in /proc (a process that exits while it is read is skipped)."""
    found, queue = set(), [pid]
    while queue:
        current = queue.pop()
        try:  # Python 3.11's glob raises if the process's task folder vanishes while it is listed
            listed = list(Path(f"/proc/{current}/task").glob("*/children"))
        except OSError:
            continue
        for children in listed:
            try:
                kids = {int(c) for c in children.read_text().split()}
            except OSError:
                continue
            queue.extend(kids - found)
            found |= kids
    return found


def _listening_addresses(pids: set[int]) -> set[tuple[str, int]]:
    """(address, port) of every TCP socket in LISTEN state that one of ``pids`` holds (/proc/net/tcp{,6})."""
    inodes = set()
    for pid in pids:
        try:
            links = [os.readlink(fd) for fd in Path(f"/proc/{pid}/fd").iterdir()]
        except OSError:
            continue
        inodes |= {link[8:-1] for link in links if link.startswith("socket:[")}
    found = set()
    for table, family in (("tcp", socket.AF_INET), ("tcp6", socket.AF_INET6)):
        for line in Path(f"/proc/net/{table}").read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] != "0A" or fields[9] not in inodes:  # 0A: LISTEN
                continue
            address, port = fields[1].split(":")
            raw = bytes.fromhex(address)  # 32-bit words in host (little-endian) order
            raw = b"".join(raw[i:i + 4][::-1] for i in range(0, len(raw), 4))
            found.add((socket.inet_ntop(family, raw), int(port, 16)))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_second_run_is_refused_naming_the_holder(gl_context, tmp_path, write_config, run_cli):
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(out)], cwd=REPO, stdout=subprocess.PIPE,
                              text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        code, _, err = run_cli("run", "-q", str(write_config(SCENES.replace("SCENES", "1"))), str(out))
        assert code == 2 and len(err.strip().splitlines()) == 1
        assert f"pid {holder.pid} on {socket.gethostname()}" in err and "in use" in err
        from hybridgen.io.coco_writer import CocoWriter

        with pytest.raises(InputError, match=f"pid {holder.pid}"):
            CocoWriter(out, mask_encoding="polygon", append=True)
    finally:
        holder.kill()
        holder.wait()
    assert not list(out.glob("*.hdf5"))
    code, _, err = run_cli("run", "-q", str(write_config(SCENES.replace("SCENES", "1"))), str(out))
    assert code == 0, err  # the lock died with its holder


def test_two_concurrent_runs_one_refused_or_both_correct(gl_context, tmp_path, write_config):
    config = write_config(SCENES.replace("SCENES", "3"))
    out = tmp_path / "out"
    first, second = _cli("run", "-q", str(config), str(out)), _cli("run", "-q", str(config), str(out))
    results = [(p.wait(timeout=300), p.stderr.read()) for p in (first, second)]
    assert [code for code, _ in results].count(0) >= 1, results
    for code, err in results:
        assert code == 0 or (code == 2 and "in use by another hybridgen run" in err), err
    shards = sorted((out / "shards").glob("*.hdf5"))
    assert len(shards) == 6 and all(verify(p) is None for p in [*shards, out / "data.hdf5"])


def test_two_concurrent_appends_lose_nothing(gl_context, tmp_path, write_config):
    out = tmp_path / "out"
    runs = [_cli("run", "-q", str(write_config(APPEND.replace("COUNT", str(n)), f"c{n}.yaml")), str(out))
            for n in (7, 5)]
    results = [(p.wait(timeout=300), p.stderr.read()) for p in runs]
    made = sum(n for n, (code, _) in zip((7, 5), results) if code == 0)
    assert made >= 5, results
    for code, err in results:
        assert code == 0 or (code == 2 and "in use" in err), err
    numbers = sorted(int(p.stem) for p in out.glob("*.hdf5"))
    assert numbers == list(range(made))  # every keypoint of every successful run, none overwritten
    samples = {}
    for path in out.glob("*.hdf5"):
        with h5py.File(path) as h5:
            samples.setdefault(int(re.search(r"number_of_samples: (\d+)", h5.attrs["config"]).group(1)), 0)
            samples[int(re.search(r"number_of_samples: (\d+)", h5.attrs["config"]).group(1))] += 1
    assert sum(samples.values()) == made and all(samples[n] == n for n in samples)


def test_planted_symlink_at_the_temporary_name_is_never_followed(gl_context, tmp_path, write_config, run_cli,
                                                                 monkeypatch):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    planted = out / ".data.hdf5.planted000.incomplete"
    planted.symlink_to(victim)
    (out / f".data.hdf5.{os.getpid()}.incomplete").symlink_to(victim)  # the old, predictable name too
    names = iter(["planted000"] + [f"fresh{i:04d}" for i in range(100)])
    monkeypatch.setattr(tempfile, "_get_candidate_names", lambda: names)
    code, _, err = run_cli("run", "-q", str(write_config(SCENES.replace("SCENES", "1").replace(
        ", keypoints_per_chunk: 2", ""))), str(out))
    assert code == 0, err
    assert victim.read_text() == "precious" and planted.is_symlink()
    assert verify(out / "data.hdf5") is None


def test_temporary_names_fit_and_paths_stay_inside(tmp_path):
    long_name = "x" * 251 + ".hdf5"  # 256 bytes: longer than ext4/tmpfs allow
    with pytest.raises(InputError, match="allows 255"):
        temporary_path(tmp_path / long_name)
    fits = tmp_path / ("y" * 250 + ".hdf5")  # 255 bytes: legal, and its temporary name must fit too
    temp = temporary_path(fits)
    assert temp.parent == tmp_path and len(temp.name) <= 255 and temp.name.endswith(".incomplete")
    for bad in ("../x", "/etc", "a/../../b", "a\0b"):
        with pytest.raises(InputError):
            confined_path(tmp_path, bad, "dataset")
    (tmp_path / "link").symlink_to("/tmp")
    with pytest.raises(InputError, match="outside"):
        confined_path(tmp_path, "link/x", "dataset")
    assert confined_path(tmp_path, "bop/ds", "dataset") == tmp_path / "bop/ds"


@pytest.mark.parametrize("signum,code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_stops_workers_and_removes_temporary_files(gl_context, tmp_path, write_config, signum, code):
    config = write_config(SCENES.replace("SCENES", "40"))
    out = tmp_path / "out"
    process = _cli("run", "-q", str(config), str(out), "--workers", "2")
    deadline = time.monotonic() + 120
    workers: set[int] = set()
    while time.monotonic() < deadline and not list((out / "shards").glob("*.hdf5")):
        workers |= _descendants(process.pid)
        time.sleep(0.1)
    workers |= _descendants(process.pid)
    assert len(workers) >= 2 and process.poll() is None
    os.kill(process.pid, signum)
    assert process.wait(timeout=60) == code
    time.sleep(0.5)
    assert not [pid for pid in workers if _alive(pid)]
    assert not list(out.rglob("*.incomplete")) and not (out / ".hybridgen.lock").exists()


def test_shard_tasks_share_the_folder_but_exclude_a_plain_run(gl_context, tmp_path, write_config, run_cli):
    """--shard i/N tasks of one array job write one folder side by side; a run without --shard (or a second
    task of the same index) is refused while one runs."""
    config = write_config(SCENES.replace("SCENES", "2"))
    out = tmp_path / "out"
    task = ("import sys, time; from hybridgen.io.output_lock import output_locks\n"
            "with output_locks([sys.argv[1]], shard=(1, 2)):\n    print('held', flush=True); time.sleep(60)\n")
    holder = subprocess.Popen([sys.executable, "-c", task, str(out)], cwd=REPO, stdout=subprocess.PIPE, text=True)
    try:  # another task, index 1, runs
        assert holder.stdout.readline().strip() == "held"
        code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "0/2")
        assert code == 0, err
        code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "1/2")
        assert code == 2 and "in use" in err
        code, _, err = run_cli("run", "-q", str(config), str(out))
        assert code == 2 and "in use" in err
    finally:
        holder.kill()
        holder.wait()
    code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "1/2")
    assert code == 0, err
    assert verify(out / "data.hdf5") is None


def test_sigterm_stops_the_ray_cluster_the_run_started(gl_context, tmp_path, write_config):
    pytest.importorskip("ray")
    config = write_config(SCENES.replace("SCENES", "40"))
    out = tmp_path / "out"
    process = _cli("run", "-q", str(config), str(out), "--executor", "ray", "--workers", "2")
    deadline = time.monotonic() + 180
    started: set[int] = set()
    while time.monotonic() < deadline and not list((out / "shards").glob("*.hdf5")):
        started |= _descendants(process.pid)
        time.sleep(0.2)
    started |= _descendants(process.pid)
    assert process.poll() is None and len(started) >= 3  # gcs, raylet, workers ...
    listening = _listening_addresses(started | {process.pid})
    assert len(listening) >= 4, listening  # driver, gcs, raylet, agents, workers
    # only loopback (Ray puts a loopback node address on the machine's reachable one unless told not to)
    assert {address for address, _ in listening} <= {"127.0.0.1", "::ffff:127.0.0.1", "::1"}, listening
    os.kill(process.pid, signal.SIGTERM)
    assert process.wait(timeout=120) == 143
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and [pid for pid in started if _alive(pid)]:
        time.sleep(0.5)
    assert not [pid for pid in started if _alive(pid)]
