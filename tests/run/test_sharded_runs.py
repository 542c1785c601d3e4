"""Sharded runs: same bytes with 1 or 2 workers, resume after SIGKILL, --shard i/N, the virtual index."""
from __future__ import annotations

import hashlib
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

from tests.conftest import REPO
from tests.run.scene_configs import floor_and_object

CONFIG = floor_and_object(
    initializer="seed: 5, number_of_scenes: 3, keypoints_per_chunk: 2", width=40, height=30, keypoints=5,
    look_at="{provider: getter.POI, selector: {name: ball}}",
    renderer="  - name: renderer.RgbRenderer\n    config: {samples: 2, render_depth: true, map_by: [class, instance]}")


def _digests(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith(".")}


def _cli(config: Path, out: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "hybridgen", "run", "-q", str(config), str(out), *extra],
                            cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_index_presents_all_scenes(gl_context, tmp_path, write_config, run_cli):
    config = write_config(CONFIG)
    code, _, err = run_cli("run", "-q", str(config), str(tmp_path / "out"))
    assert code == 0, err
    shards = sorted(p.name for p in (tmp_path / "out/shards").iterdir() if not p.name.startswith("."))
    assert len(shards) == 9 and shards[0] == "scene_000000_chunk_00000.hdf5"
    with h5py.File(tmp_path / "out/data.hdf5") as index:
        assert index["colors"].is_virtual and index["colors"].shape == (15, 30, 40, 3)
        np.testing.assert_array_equal(index["scene_index"][()], np.repeat([0, 1, 2], 5))
        np.testing.assert_array_equal(index["keypoint_index"][()], np.tile(np.arange(5), 3))
        assert index["object_states"].shape == (3,) and index.attrs["number_of_scenes"] == 3
        with h5py.File(tmp_path / "out/shards/scene_000001_chunk_00002.hdf5") as shard:
            np.testing.assert_array_equal(index["depth"][9], shard["depth"][0])  # scene 1, keypoint 4
            np.testing.assert_array_equal(index["colors"][9], shard["colors"][0])
        # scenes differ (their own seeds), keypoints within a scene too
        assert not np.array_equal(index["cam2world"][0], index["cam2world"][5])


def _clear(folder: Path) -> None:
    for path in sorted(folder.rglob("*"), reverse=True):
        path.unlink() if path.is_file() else path.rmdir()


def test_one_or_two_workers_same_bytes(gl_context, tmp_path, write_config):
    """Every file records the resolved config (which names the output folder), so both runs use one folder."""
    config = write_config(CONFIG)
    out = tmp_path / "out"
    assert _cli(config, out).wait(timeout=300) == 0
    one = _digests(out)
    _clear(out)
    assert _cli(config, out, "--workers", "2").wait(timeout=300) == 0
    assert _digests(out) == one and len(one) == 10


def _shard_files(out: Path) -> set[str]:
    return {p.name for p in (out / "shards").iterdir()} if (out / "shards").is_dir() else set()


def _first_shard_write(process: subprocess.Popen, out: Path) -> None:
    """Returns once the run creates a file under shards/ that was not there when it started (or once it ends);
    polled every 5 ms."""
    before = _shard_files(out)
    while process.poll() is None and _shard_files(out) <= before:
        time.sleep(0.005)


def test_sigkill_at_random_moments_then_rerun_gives_identical_files(gl_context, tmp_path, write_config):
    """Kill moments are drawn within the working phase measured on the reference run (first shard file to exit),
    so they land mid-run on a fast machine as on a slow one."""
    config = write_config(CONFIG)
    out = tmp_path / "out"
    process = _cli(config, out)
    _first_shard_write(process, out)
    working = time.monotonic()
    assert process.wait(timeout=300) == 0
    working = time.monotonic() - working
    reference = _digests(out)
    _clear(out)
    rng = random.Random(3)
    kills = 0
    for _ in range(12):
        process = _cli(config, out)
        _first_shard_write(process, out)
        time.sleep(rng.uniform(0.0, 0.8) * working)
        if process.poll() is None:
            os.kill(process.pid, signal.SIGKILL)
            process.wait()
            kills += 1
            final = [p for p in out.rglob("*.hdf5") if not p.name.startswith(".")]
            for path in final:  # whatever carries a final name is complete and readable
                with h5py.File(path) as h5:
                    assert len(h5.keys()) > 0
        elif process.returncode == 0:
            break
    else:
        assert _cli(config, out).wait(timeout=300) == 0
    assert kills >= 1
    assert _cli(config, out).wait(timeout=300) == 0  # nothing left to do: resumes to the same result
    assert _digests(out) == reference


def test_shard_subsets_then_index(gl_context, tmp_path, write_config, run_cli):
    config = write_config(CONFIG)
    out = tmp_path / "out"
    code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "0/2")
    assert code == 0, err
    scenes = {p.name[:12] for p in (out / "shards").glob("scene_*.hdf5")}
    assert scenes == {"scene_000000", "scene_000002"} and not (out / "data.hdf5").exists()
    code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "1/2")
    assert code == 0, err
    assert (out / "data.hdf5").exists()
    code, _, err = run_cli("run", "-q", str(config), str(out), "--shard", "2/2")
    assert code == 2 and "0 <= i < N" in err


def test_ray_executor_gives_the_same_bytes(gl_context, tmp_path, write_config):
    """A real local Ray cluster (started by the run) executes the units; files equal the pool's."""
    import pytest

    pytest.importorskip("ray")
    config = write_config(CONFIG.replace("number_of_scenes: 3", "number_of_scenes: 2"))
    out = tmp_path / "out"
    assert _cli(config, out).wait(timeout=300) == 0
    reference = _digests(out)
    _clear(out)
    process = _cli(config, out, "--executor", "ray", "--workers", "2")
    _, err = process.communicate(timeout=600)
    assert process.returncode == 0, err[-2000:]
    assert _digests(out) == reference
