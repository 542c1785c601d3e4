"""Input file hashes are remembered by file identity: a rerun reads no unchanged input, and any change -
even one that restores size and mtime - is hashed again."""
from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import pytest

from hybridgen.io import file_identity
from hybridgen.run import input_hashes
from hybridgen.run.input_hashes import InputHashes


def _settled(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


@pytest.fixture
def no_settling(monkeypatch):
    """Files written by the test count as settled at once (else they are hashed but not remembered)."""
    monkeypatch.setattr(file_identity, "SETTLE_NS", 0)  # the racily-clean guard lives in io.file_identity


def test_unchanged_files_are_not_read_again(tmp_path, no_settling, monkeypatch):
    cache = tmp_path / "cache/input_hashes.json"
    files = [_settled(tmp_path / f"f{i}.bin", os.urandom(1000 + i)) for i in range(3)]
    first = InputHashes(cache)
    digests = [first.sha256(p) for p in files]
    first.save()
    assert digests == [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]
    assert (first.hashed, first.reused) == (3, 0) and cache.is_file()
    monkeypatch.setattr(input_hashes, "file_sha256", lambda path: pytest.fail(f"{path} was read again"))
    again = InputHashes(cache)
    assert [again.sha256(p) for p in files] == digests and (again.hashed, again.reused) == (0, 3)


def test_a_change_that_restores_size_and_mtime_is_hashed_again(tmp_path, no_settling):
    cache = tmp_path / "input_hashes.json"
    path = _settled(tmp_path / "texture.png", b"A" * 4096)
    stat = path.stat()
    hashes = InputHashes(cache)
    old = hashes.sha256(path)
    hashes.save()
    time.sleep(0.05)  # past the kernel's coarse timestamp tick, so the ctime differs
    path.write_bytes(b"B" * 4096)  # same size
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # mtime put back (as rsync -t / cp -p do)
    assert path.stat().st_size == stat.st_size and path.stat().st_mtime_ns == stat.st_mtime_ns
    again = InputHashes(cache)
    new = again.sha256(path)
    assert new == hashlib.sha256(b"B" * 4096).hexdigest() != old and again.hashed == 1


def test_a_replaced_file_is_hashed_again(tmp_path, no_settling):
    """Another file renamed over the name (new inode), same size and mtime: hashed again."""
    cache = tmp_path / "input_hashes.json"
    path = _settled(tmp_path / "mesh.obj", b"v 0 0 0\n")
    hashes = InputHashes(cache)
    hashes.sha256(path)
    hashes.save()
    other = _settled(tmp_path / "other.obj", b"v 1 1 1\n")
    os.utime(other, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns))
    os.replace(other, path)
    assert InputHashes(cache).sha256(path) == hashlib.sha256(b"v 1 1 1\n").hexdigest()


def test_files_changed_just_now_are_not_remembered(tmp_path):
    """A file modified within the timestamp tick of its hashing could change again unseen (git's 'racily
    clean' case): its hash is used, not cached."""
    cache = tmp_path / "input_hashes.json"
    path = _settled(tmp_path / "fresh.bin", b"x" * 10)
    hashes = InputHashes(cache)
    assert hashes.sha256(path) == hashlib.sha256(b"x" * 10).hexdigest()
    hashes.save()
    assert not cache.exists()
    assert InputHashes(cache).sha256(path) == hashlib.sha256(b"x" * 10).hexdigest()


def test_damaged_cache_is_ignored_and_rewritten(tmp_path, no_settling):
    cache = tmp_path / "input_hashes.json"
    path = _settled(tmp_path / "a.bin", b"abc")
    cache.write_bytes(b"\x00{not json")
    hashes = InputHashes(cache)
    assert hashes.sha256(path) == hashlib.sha256(b"abc").hexdigest() and hashes.hashed == 1
    hashes.save()
    stored = json.loads(cache.read_text())["files"]
    assert list(stored) == [os.path.abspath(path)]
    wrong = {os.path.abspath(path): [*list(stored.values())[0][:5], "0" * 64, 0]}  # a forged digest, same identity
    cache.write_text(json.dumps({"format": 2, "files": wrong}))  # another format: not trusted
    assert InputHashes(cache).sha256(path) == hashlib.sha256(b"abc").hexdigest()


def test_cache_is_bounded_and_merges_concurrent_runs(tmp_path, no_settling, monkeypatch):
    monkeypatch.setattr(input_hashes, "MAX_ENTRIES", 3)
    cache = tmp_path / "input_hashes.json"
    files = [_settled(tmp_path / f"{i}.bin", bytes([i]) * 10) for i in range(5)]
    one, two = InputHashes(cache), InputHashes(cache)  # two runs at the same time
    one.sha256(files[0])
    two.sha256(files[1])
    one.save()
    two.save()
    assert len(json.loads(cache.read_text())["files"]) == 2  # the second merged the first's entry
    three = InputHashes(cache)
    for path in files[2:]:
        three.sha256(path)
    three.save()
    assert len(json.loads(cache.read_text())["files"]) == 3


def test_fingerprint_of_a_named_folder_reuses_its_hashes(tmp_path, no_settling, monkeypatch):
    """A config naming a folder of files: the second fingerprint reads none of them and is identical; an
    edited file changes exactly its own key. HYBRIDGEN_CACHE_DIR=off writes no cache."""
    from hybridgen.config.config_file import load_config
    from hybridgen.run.fingerprint import run_fingerprint

    textures = tmp_path / "textures"
    textures.mkdir()
    for i in range(20):
        (textures / f"t{i:02d}.png").write_bytes(os.urandom(256))
    config_path = tmp_path / "config.yaml"
    config_path.write_text("modules:\n  - name: main.Initializer\n    config: {seed: 1}\n"
                           f"  - name: material.MaterialRandomizer\n    config: {{textures: {textures}}}\n")
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path / "cache"))
    config = load_config(str(config_path))
    cold = InputHashes.default()
    first = run_fingerprint(config, cold)
    assert cold.hashed == 20 and sum(key.startswith("input:") for key in first) == 20
    warm = InputHashes.default()
    assert run_fingerprint(config, warm) == first and (warm.hashed, warm.reused) == (0, 20)
    (textures / "t07.png").write_bytes(os.urandom(256))
    edited = run_fingerprint(config)
    assert [key for key in first if first[key] != edited[key]] == ["input:textures/t07.png"]
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", "off")
    (tmp_path / "cache/input_hashes.json").unlink()
    assert run_fingerprint(config) == edited and not (tmp_path / "cache/input_hashes.json").exists()
