"""Fixtures of the render tests."""
from __future__ import annotations

import pytest

from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit


@pytest.fixture
def jit_variant() -> str:
    """The Mitsuba variant hybridgen picks here, for tests of its own path tracer (render/pathtrace/clamped_path.py), which
    runs in the JIT variants only: skips where the choice is ``scalar_rgb``."""
    chosen = choose_variant(None)
    if not is_jit(chosen):
        pytest.skip("hybridgen's path tracer needs a JIT Mitsuba variant (llvm_ad_rgb or cuda_ad_rgb)")
    return chosen
