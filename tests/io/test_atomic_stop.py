"""A stop request (SIGTERM) arriving while a temporary output file is being made never leaves it behind."""
from __future__ import annotations

import tempfile

import pytest

from hybridgen import stop_request
from hybridgen.io import atomic


def test_a_stop_right_after_the_file_is_created_still_removes_it(tmp_path, monkeypatch):
    real_mkstemp = tempfile.mkstemp

    def mkstemp_then_signal(*args, **kwargs):
        made = real_mkstemp(*args, **kwargs)
        stop_request.request_stop(143)  # what the SIGTERM handler does, at the worst moment
        return made

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp_then_signal)
    try:
        with pytest.raises(SystemExit) as stopped:
            atomic.temporary_path(tmp_path / "data.hdf5")
        assert stopped.value.code == 143
        made = list(tmp_path.glob(".data.hdf5.*.incomplete"))
        assert len(made) == 1  # created, and listed before the request was raised ...
        assert made[0] in atomic._LIVE  # noqa: SLF001
        atomic.remove_live_temporaries()  # ... so the exit path removes it
        assert not made[0].exists()
    finally:
        stop_request.clear()
