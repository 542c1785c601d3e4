"""The wheel holds every package: pyproject.toml's explicit package list names each folder of hybridgen/ that has
an ``__init__.py`` (an editable install finds a missing one anyway; a built wheel would not ship it)."""
from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_folder_is_listed_in_pyproject():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "hybridgen").rglob("__init__.py")}
    assert found - listed == set(), f"add to pyproject.toml's packages: {sorted(found - listed)}"
    assert listed - found == {"hybridgen.shaders"}  # the one package mapped from another folder (package-dir)
