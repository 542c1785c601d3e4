"""The tools import each other as top-level modules (``python tools/X.py`` puts tools/ first on sys.path), so the
tests of tools/ put tools/ on sys.path too before they import a tool."""
from __future__ import annotations

import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[2] / "tools"
if str(TOOLS) not in sys.path:
    sys.path.insert(0, str(TOOLS))
