"""BlenderProc's internal module paths (``blenderproc.python...``) under ``hybridgen run``: every module BlenderProc
2.8's public API re-exports from is importable and each re-exported name is the same object as hybridgen's
``bproc.<area>.<name>``; a helper class hybridgen lacks imports, and raises one line naming it when used."""
from __future__ import annotations

import ast
import importlib.util
import json
from pathlib import Path

import pytest

from hybridgen.bproc.internal_modules import INTERNAL_MODULES


def _api_imports() -> list[tuple[str, str, list[str]]]:
    """(area, BlenderProc module, names) of every ``from blenderproc.python.X import ...`` in BlenderProc 2.8's
    installed ``blenderproc/api/<area>/__init__.py`` files (read as syntax, not run)."""
    spec = importlib.util.find_spec("blenderproc")
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("the blenderproc package (test extra) is not installed")
    api = Path(list(spec.submodule_search_locations)[0]) / "api"
    found = []
    for init in sorted(api.glob("*/__init__.py")):
        for node in ast.parse(init.read_text()).body:
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("blenderproc.python."):
                found.append((init.parent.name, node.module, [alias.name for alias in node.names]))
    return found


def test_every_module_the_api_reexports_from_is_in_the_table() -> None:
    imports = _api_imports()
    assert len(imports) > 40
    assert sorted({module for _, module, _ in imports} - set(INTERNAL_MODULES)) == []


def test_reexported_names_are_hybridgens_objects(run_cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    wanted = [(area, module, name) for area, module, names in _api_imports() for name in names]
    script = "\n".join([
        "import importlib, json, sys", "import blenderproc as bproc",
        f"wanted = {wanted!r}", "same = []",
        "for area, module, name in wanted:",
        "    internal = getattr(importlib.import_module(module), name)",
        "    public = getattr(getattr(bproc, area), name)",
        # a name bproc lacks is a fresh one-line stand-in per lookup: compare what it says
        "    same.append(internal is public or getattr(internal, '__doc__', 1) == getattr(public, '__doc__', 2))",
        "json.dump(same, open(sys.argv[1], 'w'))"])
    (tmp_path / "main.py").write_text(script)
    code, _, err = run_cli("run", str(tmp_path / "main.py"), "same.json")
    assert code == 0, err
    same = json.loads((tmp_path / "same.json").read_text())
    assert len(same) == len(wanted) and [w for w, s in zip(wanted, same) if not s] == []


def test_examples_imports_work_and_helpers_raise_one_line(run_cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    head = ("import blenderproc as bproc\n"
            "from blenderproc.python.utility.SetupUtility import SetupUtility\n"
            "from blenderproc.python.utility.Utility import Utility\n"
            "import blenderproc.python.types.MeshObjectUtility as mou\n")
    (tmp_path / "main.py").write_text(head + "import sys\n"
                                      "assert Utility.resolve_path('a/b') == bproc.utility.resolve_path('a/b')\n"
                                      "assert mou.MeshObject is bproc.types.MeshObject\n"
                                      "assert mou.create_primitive is bproc.object.create_primitive\n"
                                      "open(sys.argv[1], 'w').write('ok')\n")
    code, _, err = run_cli("run", str(tmp_path / "main.py"), "ok.txt")
    assert code == 0 and (tmp_path / "ok.txt").read_text() == "ok", err
    for use, line in (("SetupUtility.setup_pip(['x'])",
                       "blenderproc.python.utility.SetupUtility.SetupUtility.setup_pip is not supported"),
                      ("Utility.get_temporary_directory()",
                       "blenderproc.python.utility.Utility.Utility.get_temporary_directory is not supported"),
                      ("import blenderproc.python.utility.Nope", "import blenderproc.python.utility.Nope: the "
                                                                 "module is not supported by hybridgen yet")):
        (tmp_path / "main.py").write_text(head + use + "\n")
        code, _, err = run_cli("run", str(tmp_path / "main.py"))
        assert code == 2 and line in err and len(err.strip().splitlines()) == 1, err
