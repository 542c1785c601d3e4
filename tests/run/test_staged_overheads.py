"""What a staged (resumable, non-sharded) run pays besides rendering: its config is parsed once per process,
and the bytes stay those of the directly written file."""
from __future__ import annotations

from hybridgen.config import config_file
from hybridgen.run import pipeline, scene_reuse
from tests.run.test_staged_resume import PARTS, _units_rendered, reference  # noqa: F401 - fixture


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
