"""A non-sharded run resumes: its keypoints are rendered as verified parts in a hidden staging folder and
merged into one ordinary data.hdf5 - the same bytes as writing the file directly, killed or not.

A run is SIGKILLed (a real kill of a real process) in the middle of a part, or after some parts exist and
one is then damaged or deleted; the rerun must reuse exactly the intact parts (counted from its unit log
lines) and give a file byte-identical to an uninterrupted run into the same folder (the file records its
output folder, so comparisons use one folder).
"""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

from hybridgen.io.integrity import verify
from hybridgen.run.staged_output import (DEFAULT_CHUNK_KEYPOINTS, DEFAULT_LABEL_CHUNK_KEYPOINTS, JOURNAL_ATTR,
                                         staging_folder_name)
from tests.conftest import REPO
from tests.run.test_resume_integrity import SINGLE

CONFIG = (SINGLE.replace("number_of_samples: 3", "number_of_samples: 7")
          .replace("{render_normals: false}", "{map_by: [class, instance]}")
          .replace("  - name: writer.Hdf5Writer\n",
                   "  - name: writer.Hdf5Writer\n    config: {resume_chunk_keypoints: 2}\n"))
PARTS = 4  # 7 keypoints in parts of 2
COLOR = CONFIG.replace("  - name: renderer.SegMapRenderer",
                       "  - name: renderer.RgbRenderer\n    config: {samples: 2}\n  - name: renderer.SegMapRenderer")

# Runs the CLI in a child process that SIGKILLs itself while the writer of part CHUNK receives keypoint AT
# (AT = -1: as part CHUNK starts, before it renders anything).
KILLER = textwrap.dedent("""
    import os, signal, sys
    from hybridgen.cli import main
    from hybridgen.io import hdf5_single
    from hybridgen.run import unit_task as runner
    chunk, at = int(sys.argv[1]), int(sys.argv[2])
    run_unit, write = runner.run_unit, hdf5_single.Hdf5SingleFileWriter.write
    def unit(*call):
        if call[3].chunk == chunk and at < 0:
            os.kill(os.getpid(), signal.SIGKILL)
        return run_unit(*call)
    def killing_write(self, index, values):
        if f"chunk_{chunk:05d}" in self.path.name and index == at:
            os.kill(os.getpid(), signal.SIGKILL)
        return write(self, index, values)
    runner.run_unit = unit
    hdf5_single.Hdf5SingleFileWriter.write = killing_write
    sys.exit(main(["run", "-q", *sys.argv[3:]]))
""")


def _killed_run(config: Path, out: Path, chunk: int, at: int) -> None:
    done = subprocess.run([sys.executable, "-c", KILLER, str(chunk), str(at), str(config), str(out)], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == -9, done.stderr


def _units_rendered(log: str) -> list[str]:
    return sorted(line.split("unit ")[1].split(":")[0] for line in log.splitlines() if "unit scene_" in line)


@pytest.fixture
def reference(gl_context, tmp_path, write_config, run_cli):
    """An uninterrupted run's data.hdf5 bytes; the folder is emptied again for the test's own runs."""
    config = write_config(CONFIG.replace("SEED", "1"))
    out = tmp_path / "out"
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == [f"scene_000000_chunk_{c:05d}" for c in range(PARTS)]
    assert not (out / staging_folder_name("data.hdf5")).exists()
    data = (out / "data.hdf5").read_bytes()
    (out / "data.hdf5").unlink()
    return config, out, data


def direct_bytes(config: Path, out: Path) -> bytes:
    """The bytes of ``config``'s data.hdf5 written directly (in process, no staging) into ``out``; the file is
    removed again so that a staged run can write the same folder."""
    from hybridgen.config.config_file import load_config
    from hybridgen.run.fingerprint import FINGERPRINT_ATTR, fingerprint_text, run_fingerprint
    from hybridgen.run.pipeline import build_modules, execute

    loaded = load_config(str(config), [str(out)])
    context = execute(loaded, build_modules(loaded),
                      attributes={FINGERPRINT_ATTR: fingerprint_text(run_fingerprint(loaded))})
    direct = context.outputs[0].read_bytes()
    (out / "data.hdf5").unlink()
    return direct


def test_staged_file_is_the_directly_written_file(gl_context, tmp_path, write_config, run_cli):
    """Merging parts gives the bytes of the file the writer streams directly (color, labels and JSON)."""
    config = write_config(COLOR.replace("SEED", "2"))
    out = tmp_path / "out"
    direct = direct_bytes(config, out)
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert len(_units_rendered(err)) == PARTS
    staged = (out / "data.hdf5").read_bytes()
    assert staged == direct
    with h5py.File(out / "data.hdf5", "r") as h5:
        assert JOURNAL_ATTR not in h5.attrs and "chunk_index" not in h5.attrs
        assert h5["colors"].shape == (7, 12, 16, 3) and h5["colors"].chunks == (1, 12, 16, 3)
        assert np.array_equal(h5["keypoint_index"][()], np.arange(7))
        assert h5["instance_attribute_maps"].shape == (7,)


@pytest.mark.parametrize("at", [0, 1], ids=["kill-at-first-keypoint", "kill-mid-part"])
def test_killed_run_resumes_to_the_same_bytes(reference, run_cli, at):
    config, out, data = reference
    _killed_run(config, out, chunk=2, at=at)
    staging = out / staging_folder_name("data.hdf5")
    assert sorted(p.name for p in staging.glob("scene_*.hdf5")) == \
        ["scene_000000_chunk_00000.hdf5", "scene_000000_chunk_00001.hdf5"]
    assert not (out / "data.hdf5").exists()
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == ["scene_000000_chunk_00002", "scene_000000_chunk_00003"]
    assert "resumed: 2 unit(s)" in err
    assert (out / "data.hdf5").read_bytes() == data
    assert verify(out / "data.hdf5") is None
    assert not staging.exists() and [p.name for p in out.iterdir() if p.name.endswith(".incomplete")] == []


def _flip_bit(path: Path) -> None:
    with h5py.File(path, "r+") as h5:
        dset = h5["depth"]
        mask, chunk = dset.id.read_direct_chunk((0, 0, 0))
        damaged = bytearray(chunk)
        damaged[len(damaged) // 2] ^= 0x10
        dset.id.write_direct_chunk((0, 0, 0), bytes(damaged), mask)


@pytest.mark.parametrize("damage", ["bit-flip", "truncate", "delete"])
def test_damaged_part_is_rendered_again(reference, run_cli, damage):
    config, out, data = reference
    _killed_run(config, out, chunk=3, at=-1)
    part = out / staging_folder_name("data.hdf5") / "scene_000000_chunk_00001.hdf5"
    if damage == "bit-flip":
        _flip_bit(part)
    elif damage == "truncate":
        part.write_bytes(part.read_bytes()[:1000])
    else:
        part.unlink()
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == ["scene_000000_chunk_00001", "scene_000000_chunk_00003"]
    assert (damage == "delete") != ("rendering it again" in err)
    assert (out / "data.hdf5").read_bytes() == data


def test_parts_of_another_config_are_refused(reference, write_config, run_cli):
    config, out, data = reference
    _killed_run(config, out, chunk=2, at=0)
    changed = write_config(CONFIG.replace("SEED", "5"), "changed.yaml")
    code, _, err = run_cli("run", "-q", str(changed), str(out))
    assert code == 2 and "main.Initializer#0.seed" in err and "--restart" in err
    assert len(err.strip().splitlines()) == 1 and not (out / "data.hdf5").exists()
    code, _, err = run_cli("run", str(changed), str(out), "--restart")
    assert code == 0 and "--restart: discarded 2" in err
    assert len(_units_rendered(err)) == PARTS
    assert (out / "data.hdf5").read_bytes() != data
    code, _, err = run_cli("run", "-q", str(config), str(out), "--restart")
    assert code == 0 and (out / "data.hdf5").read_bytes() == data


@pytest.mark.parametrize(("renderers", "setting", "expected"), [
    ("labels", "", DEFAULT_LABEL_CHUNK_KEYPOINTS), ("color", "", DEFAULT_CHUNK_KEYPOINTS), ("color", "0", None),
    ("labels", "0", None), ("labels", "7", 7)])
def test_which_runs_are_staged_by_default(tmp_path, write_config, renderers, setting, expected):
    from hybridgen.config.config_file import load_config
    from hybridgen.run.pipeline import build_modules, staged_plan

    text = (COLOR if renderers == "color" else CONFIG).replace("SEED", "1")
    text = text.replace("{resume_chunk_keypoints: 2}", f"{{resume_chunk_keypoints: {setting}}}" if setting else "{}")
    config = load_config(str(write_config(text)), [str(tmp_path / "out")])
    plan = staged_plan(build_modules(config))
    assert (plan.chunk_size if plan else None) == expected
    if plan is not None:
        assert plan.staged and plan.folder == ".data.hdf5.parts" and plan.scenes == 1


def test_resumed_parts_build_the_scene_once_and_give_the_direct_bytes(reference, run_cli, monkeypatch):
    """A killed label-only staged run, rerun in this process: the scene-building modules (loaders, camera
    sampling) run once for both missing parts, and the merged file is the file a direct write gives."""
    from hybridgen.config.config_file import load_config
    from hybridgen.modules.camera_sampler import CameraSampler
    from hybridgen.modules.primitive_loader import PrimitiveLoader
    from hybridgen.run.fingerprint import FINGERPRINT_ATTR, fingerprint_text, run_fingerprint
    from hybridgen.run.pipeline import build_modules, execute

    config, out, data = reference
    _killed_run(config, out, chunk=2, at=1)
    calls: list[str] = []
    for cls in (CameraSampler, PrimitiveLoader):
        original = cls.run
        monkeypatch.setattr(cls, "run", lambda self, context, run=original: (calls.append(self.module_name),
                                                                             run(self, context))[1])
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == ["scene_000000_chunk_00002", "scene_000000_chunk_00003"]
    assert sorted(calls) == ["camera.CameraSampler", "loader.PrimitiveLoader", "loader.PrimitiveLoader"]
    assert (out / "data.hdf5").read_bytes() == data
    (out / "data.hdf5").unlink()
    loaded = load_config(str(config), [str(out)])
    context = execute(loaded, build_modules(loaded),
                      attributes={FINGERPRINT_ATTR: fingerprint_text(run_fingerprint(loaded))})
    assert context.outputs[0].read_bytes() == data
    with h5py.File(out / "data.hdf5", "r") as h5:  # every keypoint rendered, each from its own camera
        assert h5["depth"].shape[0] == 7 and len({h5["depth"][i].tobytes() for i in range(7)}) == 7


def test_failed_run_keeps_completed_parts_and_resumes(reference, run_cli, monkeypatch):
    """An error (not a kill) in the third part: the run exits 2, keeps the two completed parts (a failure
    before the first part completes leaves no staging folder: tests/config/test_config_errors.py), and the
    rerun renders the rest into the reference bytes."""
    from hybridgen.errors import InputError
    from hybridgen.io.hdf5_single import Hdf5SingleFileWriter

    config, out, data = reference
    write = Hdf5SingleFileWriter.write

    def failing_write(self, index, values):
        if "chunk_00002" in self.path.name:
            raise InputError("simulated failure in part 2")
        return write(self, index, values)

    monkeypatch.setattr(Hdf5SingleFileWriter, "write", failing_write)
    code, _, err = run_cli("run", "-q", str(config), str(out))
    assert code == 2 and "simulated failure in part 2" in err
    staging = out / staging_folder_name("data.hdf5")
    assert sorted(p.name for p in staging.iterdir()) == ["scene_000000_chunk_00000.hdf5",
                                                          "scene_000000_chunk_00001.hdf5"]
    monkeypatch.setattr(Hdf5SingleFileWriter, "write", write)
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0 and "resumed: 2 unit(s)" in err
    assert (out / "data.hdf5").read_bytes() == data and not staging.exists()
