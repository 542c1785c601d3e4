"""A fresh BlenderProc session for the bproc writer tests: ``bproc.init()`` on an emptied session, emptied again
afterwards (``init()`` may run once per session, and the next test's must set BlenderProc's defaults)."""
from __future__ import annotations

from typing import Any, Iterator

import pytest


@pytest.fixture
def bproc() -> Iterator[Any]:
    import hybridgen.bproc as bproc
    from hybridgen.bproc.session import reset

    reset(keep_initialized=False)
    bproc.init()
    bproc.camera.set_resolution(32, 24)
    yield bproc
    reset(keep_initialized=False)
