"""Per-process memos keyed by file identity (hybridgen.io.file_identity): a settled, unchanged file is read
once; any change - even one that restores size and mtime - is read again; a racily clean file is never
remembered; and a run's fingerprint and its mesh cache share one scan and one hash of an OBJ."""
from __future__ import annotations

import builtins
import hashlib
import io
import os
import shutil
import time
from pathlib import Path

import pytest

from hybridgen.io import file_identity, mesh_references
from hybridgen.io.file_identity import IdentityMemo, content_sha256
from tests.conftest import REPO


@pytest.fixture
def no_settling(monkeypatch):
    """Files written by the test count as settled at once (else they are read but not remembered)."""
    monkeypatch.setattr(file_identity, "SETTLE_NS", 0)


def _reading_memo() -> tuple[IdentityMemo[bytes], list[Path]]:
    reads: list[Path] = []

    def read(path: Path) -> bytes:
        reads.append(path)
        return path.read_bytes()

    return IdentityMemo(read), reads


def test_a_settled_unchanged_file_is_read_once(tmp_path, no_settling):
    path = tmp_path / "a.obj"
    path.write_bytes(b"v 0 0 0\n")
    memo, reads = _reading_memo()
    assert memo(path) == memo(path) == memo(Path(os.path.relpath(path))) == b"v 0 0 0\n"
    assert len(reads) == 1 and (memo.computed, memo.reused) == (1, 2)


def test_a_change_that_restores_size_and_mtime_is_read_again(tmp_path, no_settling):
    path = tmp_path / "a.mtl"
    path.write_bytes(b"A" * 64)
    stat = path.stat()
    memo, reads = _reading_memo()
    assert memo(path) == b"A" * 64
    time.sleep(0.05)  # past the kernel's coarse timestamp tick, so the ctime differs
    path.write_bytes(b"B" * 64)
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # mtime put back (as rsync -t / cp -p do)
    assert path.stat().st_size == stat.st_size and path.stat().st_mtime_ns == stat.st_mtime_ns
    assert memo(path) == b"B" * 64 and len(reads) == 2
    other = tmp_path / "other.mtl"  # another file renamed over the name: a new inode
    other.write_bytes(b"C" * 64)
    os.utime(other, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    os.replace(other, path)
    assert memo(path) == b"C" * 64 and len(reads) == 3


def test_a_racily_clean_file_is_used_but_not_remembered(tmp_path):
    """Changed within SETTLE_NS of being read, a file could change again within the same timestamp tick and
    keep its identity: every call reads it (git's 'racily clean' rule)."""
    path = tmp_path / "fresh.obj"
    path.write_bytes(b"x")
    memo, reads = _reading_memo()
    assert memo(path) == memo(path) == b"x" and len(reads) == 2
    memo.remember(path, path.stat(), b"forged")  # a value for a fresh file is not taken either
    assert memo(path) == b"x" and len(reads) == 3
    settled = time.time_ns() + 2 * file_identity.SETTLE_NS
    assert not file_identity.is_settled(path.stat()) and file_identity.is_settled(path.stat(), settled)


def test_memo_is_bounded(tmp_path, no_settling):
    memo: IdentityMemo[bytes] = IdentityMemo(Path.read_bytes, max_entries=2)
    files = [tmp_path / f"{i}.obj" for i in range(3)]
    for i, path in enumerate(files):
        path.write_bytes(bytes([i]))
        memo(path)
    memo(files[2])
    memo(files[0])  # the oldest entry was dropped: read again
    assert (memo.computed, memo.reused) == (4, 1)


def test_fingerprint_and_mesh_cache_share_one_scan_and_one_hash(tmp_path, no_settling, monkeypatch):
    """A labels run's fingerprint scans the OBJ for MTL libraries and hashes it; the mesh cache's key then
    needs both again - from the memos, without reading the OBJ."""
    from hybridgen.config.config_file import load_config
    from hybridgen.io.mesh_cache import cache_key
    from hybridgen.run.fingerprint import run_fingerprint

    for name in ("knot.obj", "knot.mtl", "knot.png"):
        shutil.copy(REPO / "configs/assets" / name, tmp_path / name)
    mesh = tmp_path / "knot.obj"
    config_path = tmp_path / "config.yaml"
    config_path.write_text(f"modules:\n  - name: loader.ObjLoader\n    config: {{path: {mesh}}}\n")
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path / "cache"))
    scans, hashes = mesh_references.scanned_names, content_sha256
    monkeypatch.setattr(scans, "_values", {})
    monkeypatch.setattr(hashes, "_values", {})
    before = (scans.computed, hashes.computed)
    fingerprint = run_fingerprint(load_config(str(config_path)))
    assert fingerprint["input:knot.obj"] == hashlib.sha256(mesh.read_bytes()).hexdigest()
    assert "input:knot.mtl" in fingerprint and "input:knot.png" in fingerprint
    after_fingerprint = (scans.computed, hashes.computed)
    assert after_fingerprint[0] - before[0] == 2  # the OBJ and its MTL, scanned once each
    opened = []
    real_open = io.open

    def watched_open(file, *args, **kwargs):
        opened.append(Path(file).name)
        return real_open(file, *args, **kwargs)

    with pytest.MonkeyPatch.context() as watch:
        watch.setattr(io, "open", watched_open)  # Path.read_bytes
        watch.setattr(builtins, "open", watched_open)  # hashlib.file_digest callers
        key = cache_key(mesh, {"name": None, "up_axis": "auto"})
    assert not {"knot.obj", "knot.mtl", "knot.png"} & set(opened), opened  # no input file read for the key
    assert (scans.computed, hashes.computed) == after_fingerprint
    scans.clear()
    hashes.clear()
    assert cache_key(mesh, {"name": None, "up_axis": "auto"}) == key  # the memos change no value
