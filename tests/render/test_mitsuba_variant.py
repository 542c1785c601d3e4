"""The variant probe's answer is kept on disk, keyed by what it depends on; the child runs once per key."""
from __future__ import annotations

import json
import subprocess

import pytest

from hybridgen.render.pathtrace import mitsuba_variant
from hybridgen.render.pathtrace.mitsuba_variant import PROBE_CACHE, choose_variant, is_jit, probe_key, variant_works


@pytest.fixture
def children(monkeypatch, tmp_path):
    """Probe children started (the real ones run), with a fresh cache folder and per-process cache."""
    started: list[str] = []
    real_run = subprocess.run

    def counting_run(command, *args, **kwargs):
        started.append(command[-1])
        return real_run(command, *args, **kwargs)

    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(mitsuba_variant.subprocess, "run", counting_run)
    variant_works.cache_clear()
    yield started
    variant_works.cache_clear()


def test_probe_answer_is_cached_per_backend_library_version(children, tmp_path, monkeypatch):
    variant = choose_variant(None)
    if not is_jit(variant):
        pytest.skip("no JIT variant works here: nothing is probed")
    assert children == [variant]  # the auto choice probed it (an unusable CUDA is answered in-process)
    key = probe_key(variant)
    assert json.loads((tmp_path / PROBE_CACHE).read_text()) == {key: True}

    variant_works.cache_clear()  # a new process: the answer comes from the file
    assert variant_works(variant) and children == [variant]

    (tmp_path / PROBE_CACHE).write_text(json.dumps({key: False}))  # the file's answer is the answer
    variant_works.cache_clear()
    assert not variant_works(variant) and children == [variant]

    # another backend library (e.g. libLLVM replaced by 15, which aborts at the first kernel): probed again
    import drjit as dr

    name = "cuda_version" if variant.startswith("cuda_") else "llvm_version"
    monkeypatch.setattr(dr.detail, name, lambda: (15, 0, 7))
    assert probe_key(variant) != key and probe_key(variant).endswith("|15.0.7")
    variant_works.cache_clear()
    assert variant_works(variant) and children == [variant, variant]
    assert set(json.loads((tmp_path / PROBE_CACHE).read_text())) == {key, probe_key(variant)}


def test_no_cache_with_cache_off_and_no_child_for_an_absent_backend(children, monkeypatch, tmp_path):
    import drjit as dr

    if not dr.has_backend(dr.JitBackend.CUDA):
        assert probe_key("cuda_ad_rgb") is None
        assert not variant_works("cuda_ad_rgb") and children == []
    if not dr.has_backend(dr.JitBackend.LLVM):
        pytest.skip("no LLVM backend here")
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", "off")
    answers = []
    for _ in range(2):
        variant_works.cache_clear()
        answers.append(variant_works("llvm_ad_rgb"))
    assert answers[0] == answers[1] and children == ["llvm_ad_rgb", "llvm_ad_rgb"] and not list(tmp_path.iterdir())
