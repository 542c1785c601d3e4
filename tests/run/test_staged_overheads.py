"""What a staged (resumable, non-sharded) run pays besides rendering, and that paying less keeps its bytes:
its config is parsed once per process; a run of one part writes the final file itself (no part to merge,
nothing left behind by a kill); the scene's last part runs on the built scene itself, earlier parts on copies
that a unit's changes to its scene never reach."""
from __future__ import annotations

import h5py
import pytest

from hybridgen.config import config_file
from hybridgen.io.integrity import verify
from hybridgen.run import pipeline, scene_reuse, staged_output
from hybridgen.run.staged_output import JOURNAL_ATTR, staging_folder_name
from tests.run.test_staged_resume import (CONFIG, PARTS, _killed_run, _units_rendered,  # noqa: F401 - fixture
                                          reference)

ONE_PART = CONFIG.replace("{resume_chunk_keypoints: 2}", "{resume_chunk_keypoints: 7}")  # 7 keypoints


def _direct_bytes(config, out) -> bytes:
    """The file an unstaged run of ``config`` writes into ``out`` (removed again)."""
    from hybridgen.run.fingerprint import FINGERPRINT_ATTR, fingerprint_text, run_fingerprint
    from hybridgen.run.pipeline import build_modules, execute

    loaded = config_file.load_config(str(config), [str(out)])
    context = execute(loaded, build_modules(loaded),
                      attributes={FINGERPRINT_ATTR: fingerprint_text(run_fingerprint(loaded))})
    data = context.outputs[0].read_bytes()
    context.outputs[0].unlink()
    return data


def test_a_staged_run_parses_its_config_once(reference, run_cli, monkeypatch):  # noqa: F811
    config, out, data = reference
    loads: list[str] = []

    def counted(path, args=(), env=None):
        loads.append(str(path))
        return config_file.load_config(path, args, env)

    for module in (pipeline, scene_reuse):
        monkeypatch.setattr(module, "load_config", counted)
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert len(_units_rendered(err)) == PARTS  # four parts, one scene built for them, one parse
    assert loads == [str(config)]
    assert (out / "data.hdf5").read_bytes() == data


@pytest.fixture
def one_part(gl_context, tmp_path, write_config):
    config = write_config(ONE_PART.replace("SEED", "3"), "one_part.yaml")
    out = tmp_path / "one_part"
    return config, out, _direct_bytes(config, out)


def test_a_run_of_one_part_writes_the_direct_file_without_merging(one_part, run_cli, monkeypatch):
    config, out, direct = one_part

    def no_merge(*args):
        raise AssertionError("a run of one part has nothing to merge")

    monkeypatch.setattr(staged_output, "consolidate", no_merge)
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == ["scene_000000_chunk_00000"]
    assert (out / "data.hdf5").read_bytes() == direct and verify(out / "data.hdf5") is None
    assert sorted(p.name for p in out.iterdir()) == ["data.hdf5"]  # staging folder gone, no temporary file
    with h5py.File(out / "data.hdf5", "r") as h5:
        assert JOURNAL_ATTR not in h5.attrs and "chunk_index" not in h5.attrs and h5["depth"].shape[0] == 7
    code, _, err = run_cli("run", str(config), str(out))  # complete: nothing to do
    assert code == 0 and "nothing to do" in err and (out / "data.hdf5").read_bytes() == direct


@pytest.mark.parametrize("at", [-1, 3], ids=["kill-before-rendering", "kill-mid-run"])
def test_a_killed_run_of_one_part_leaves_nothing_and_renders_again(one_part, run_cli, at):
    config, out, direct = one_part
    _killed_run(config, out, chunk=0, at=at)
    assert not (out / "data.hdf5").exists()
    staging = out / staging_folder_name("data.hdf5")
    assert [p for p in staging.glob("*.hdf5")] == []  # at most a hidden temporary file, in the staging folder
    assert [p.name for p in out.iterdir() if p.name.endswith(".incomplete")] == []
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert _units_rendered(err) == ["scene_000000_chunk_00000"] and "resumed" not in err
    assert (out / "data.hdf5").read_bytes() == direct
    assert sorted(p.name for p in out.iterdir()) == ["data.hdf5"]


def test_a_stale_whole_file_is_never_taken(one_part, reference, run_cli):  # noqa: F811
    """A whole file left in the staging folder (a run killed after writing it, before renaming it) is deleted
    by the next run: a run of several parts merges its parts, a run of one part writes its own."""
    config, out, data = reference
    _killed_run(config, out, chunk=2, at=0)
    staging = out / staging_folder_name("data.hdf5")
    stale = staging / "whole_scene_000000_chunk_00000.hdf5"
    stale.write_bytes(b"not this run's file")
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert (out / "data.hdf5").read_bytes() == data and not staging.exists()
    config, out, direct = one_part
    (out / staging_folder_name("data.hdf5")).mkdir(parents=True)
    (out / staging_folder_name("data.hdf5") / stale.name).write_bytes(b"stale")
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert (out / "data.hdf5").read_bytes() == direct


def test_a_parts_changes_to_its_scene_reach_no_later_part(reference, run_cli, monkeypatch):  # noqa: F811
    """A renderer that moves every object after rendering: each part still renders the scene as built, so the
    merged file is the direct run's (whose writer records the moved poses, as each part's does); three parts
    run on copies, the last one on the built scene itself."""
    from hybridgen.modules.segmap_renderer import SegMapRenderer

    config, out, data = reference
    render = SegMapRenderer.run

    def render_then_move(self, context):
        render(self, context)
        for obj in context.scene.objects:
            obj.local2world[:3, 3] += 0.5

    copies: list[int] = []
    copy_for = scene_reuse._copy_for
    monkeypatch.setattr(scene_reuse, "_copy_for", lambda base, unit: (copies.append(unit.chunk),
                                                                      copy_for(base, unit))[1])
    monkeypatch.setattr(SegMapRenderer, "run", render_then_move)
    direct = _direct_bytes(config, out)
    assert direct != data  # the object states record the move
    code, _, err = run_cli("run", str(config), str(out))
    assert code == 0, err
    assert copies == [0, 1, 2] and len(_units_rendered(err)) == PARTS
    assert (out / "data.hdf5").read_bytes() == direct
