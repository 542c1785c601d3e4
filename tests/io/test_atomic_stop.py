"""A stop (SIGTERM) arriving while a temporary output file is being made never leaves it behind: the main process's
request (raised once the file is listed) and a worker's handler (which deletes the listed files and exits at once,
wherever it lands)."""
from __future__ import annotations

import os

import pytest

from hybridgen import stop_request
from hybridgen.io import atomic


def _open_then(action, monkeypatch):
    """os.open as temporary_path calls it, followed by ``action(path)`` at the worst moment: the file just made."""
    real_open = os.open

    def open_then_act(path, flags, mode=0o777, *args, **kwargs):
        fd = real_open(path, flags, mode, *args, **kwargs)
        action(path)
        return fd

    monkeypatch.setattr(atomic.os, "open", open_then_act)


def test_a_stop_right_after_the_file_is_created_still_removes_it(tmp_path, monkeypatch):
    _open_then(lambda path: stop_request.request_stop(143), monkeypatch)  # what the SIGTERM handler does
    try:
        with pytest.raises(SystemExit) as stopped:
            atomic.temporary_path(tmp_path / "data.hdf5")
        monkeypatch.undo()
        assert stopped.value.code == 143
        made = list(tmp_path.glob(".data.hdf5.*.incomplete"))
        assert len(made) == 1  # created, and listed before the request was raised ...
        assert made[0] in atomic._LIVE  # noqa: SLF001
        atomic.remove_live_temporaries()  # ... so the exit path removes it
        assert not made[0].exists()
    finally:
        stop_request.clear()


def test_a_workers_handler_right_after_the_file_is_created_removes_it(tmp_path, monkeypatch):
    """A worker's SIGTERM handler does not wait for anything: it deletes the listed files and exits. The name is
    listed before the file is made, so even a handler that runs the moment it exists finds it."""
    removed: list[int] = []
    _open_then(lambda path: removed.append(atomic.remove_live_temporaries()), monkeypatch)
    atomic.temporary_path(tmp_path / "data.hdf5")
    monkeypatch.undo()
    assert removed == [1] and not list(tmp_path.iterdir())


def test_a_discarded_file_is_listed_until_it_is_deleted(tmp_path, monkeypatch):
    temp = atomic.temporary_path(tmp_path / "data.hdf5")
    real_unlink = os.unlink
    seen: list[bool] = []

    def unlink_and_look(path, *args, **kwargs):
        seen.append(temp in atomic._LIVE)  # noqa: SLF001
        return real_unlink(path, *args, **kwargs)

    monkeypatch.setattr(atomic.os, "unlink", unlink_and_look)
    atomic.discard(temp)
    monkeypatch.undo()
    assert seen == [True] and not temp.exists() and temp not in atomic._LIVE  # noqa: SLF001


def test_a_taken_name_is_skipped_and_never_followed(tmp_path, monkeypatch):
    import tempfile

    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / ".data.hdf5.taken000.incomplete").symlink_to(victim)
    names = iter(["taken000", "fresh000"])
    monkeypatch.setattr(tempfile, "_get_candidate_names", lambda: names)
    temp = atomic.temporary_path(tmp_path / "data.hdf5")
    assert temp.name == ".data.hdf5.fresh000.incomplete" and temp.stat().st_mode & 0o777 == 0o600
    assert victim.read_text() == "precious" and temp in atomic._LIVE  # noqa: SLF001
    assert tmp_path / ".data.hdf5.taken000.incomplete" not in atomic._LIVE  # noqa: SLF001
    atomic.discard(temp)


def test_every_temporary_file_that_exists_is_listed_while_another_thread_makes_them(tmp_path):
    """What a signal handler in the main thread sees while a writer thread makes temporary files: holding the
    listing lock (as remove_live_temporaries does), every such file on disk is in the list."""
    import threading
    import time

    made: list = []
    done = threading.Event()

    def writer() -> None:
        for index in range(60):
            made.append(atomic.temporary_path(tmp_path / f"part{index}.hdf5"))
        done.set()

    thread = threading.Thread(target=writer)
    thread.start()
    looks = 0
    while not done.is_set() or looks == 0:
        with atomic._LISTING:  # noqa: SLF001
            on_disk = set(tmp_path.glob(".*.incomplete"))
            assert on_disk <= atomic._LIVE  # noqa: SLF001
        looks += 1
        time.sleep(0.0005)
    thread.join()
    assert len(made) == 60 and looks > 0
    assert atomic.remove_live_temporaries() >= 60 and not list(tmp_path.iterdir())
