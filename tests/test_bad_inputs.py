"""The hostile-input corpus in tests/bad_inputs/: each config fails with one clear line naming what is wrong,
exit status 2, no traceback, and no output file under a final name.

Each file's first line is ``# expect: fragment | fragment ...``, all of which must appear in the message."""
from __future__ import annotations

from pathlib import Path

import pytest

CORPUS = Path(__file__).parent / "bad_inputs"
CASES = sorted(CORPUS.glob("*.yaml"))


def test_corpus_is_large_enough():
    assert len(CASES) >= 30


@pytest.mark.parametrize("config", CASES, ids=[p.stem for p in CASES])
def test_bad_input_fails_cleanly(config: Path, tmp_path, run_cli, monkeypatch, gl_context):
    expected = [f.strip() for f in config.read_text().splitlines()[0].removeprefix("# expect:").split("|")]
    monkeypatch.chdir(CORPUS)
    before = {p for p in CORPUS.rglob("*")}
    code, out, err = run_cli("run", "-q", str(config), str(tmp_path / "out"))
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("hybridgen: error: ") and "Traceback" not in err
    for fragment in expected:
        assert fragment in lines[0], (fragment, lines[0])
    assert not [p for p in tmp_path.rglob("*") if p.is_file() and not p.name.startswith(".")]
    assert {p for p in CORPUS.rglob("*")} == before  # nothing written beside the inputs either
