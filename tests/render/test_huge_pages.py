"""hybridgen.render.pathtrace.huge_pages: the process really runs without transparent huge pages afterwards (the
kernel's own record, /proc/self/status), unless $HYBRIDGEN_HUGE_PAGES=1 leaves them as they were."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

PROBE = """
from hybridgen.render.pathtrace.huge_pages import decline_huge_pages
declined = decline_huge_pages()
status = dict(line.split(":", 1) for line in open("/proc/self/status") if ":" in line)
print(declined, status["THP_enabled"].strip())
"""


def _probe(**env: str) -> tuple[str, str]:
    out = subprocess.run([sys.executable, "-c", PROBE], env={**os.environ, **env}, capture_output=True, text=True,
                         check=True, cwd=Path(__file__).resolve().parents[2]).stdout.split()
    return out[0], out[1]


@pytest.mark.skipif(not sys.platform.startswith("linux") or "THP_enabled" not in Path("/proc/self/status").read_text(),
                    reason="the kernel does not report THP_enabled")
def test_declined_for_the_process_unless_kept() -> None:
    assert _probe(HYBRIDGEN_HUGE_PAGES="0") == ("True", "0")
    # kept: the child's setting is what it inherited (this test process may have declined them already)
    inherited = dict(line.split(":", 1) for line in open("/proc/self/status") if ":" in line)["THP_enabled"].strip()
    assert _probe(HYBRIDGEN_HUGE_PAGES="1") == ("False", inherited)
