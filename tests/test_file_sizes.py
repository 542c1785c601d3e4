"""Files stay small: a Python file of the package or of tools/ over 300 lines says why in one line at its top
("Over 300 lines: ..." within its first 12 lines), as docs/architecture.md asks."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIMIT = 300


def oversized_without_reason(root: Path, folders: list[str]) -> list[str]:
    """``path (N lines)`` of every Python file under ``root``/``folders`` longer than :data:`LIMIT` without a reason."""
    found = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            lines = path.read_text(encoding="utf-8").splitlines()
            if len(lines) > LIMIT and not any("Over 300 lines:" in line for line in lines[:12]):
                found.append(f"{path.relative_to(root)} ({len(lines)} lines)")
    return found


def test_files_over_300_lines_give_their_reason():
    assert oversized_without_reason(ROOT, ["hybridgen", "tools"]) == []


def test_the_check_sees_a_long_file(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg/long.py").write_text('"""A long module."""\n' + "x = 1\n" * 301)
    (tmp_path / "pkg/reasoned.py").write_text('"""A long module.\n\nOver 300 lines: one table.\n"""\n' + "x = 1\n" * 301)
    (tmp_path / "pkg/short.py").write_text("x = 1\n" * 300)
    assert oversized_without_reason(tmp_path, ["pkg"]) == ["pkg/long.py (302 lines)"]
