"""tools/'s rules (tools/README.md): every benchmark times with tools/harness.py, no tool imports a benchmark, the
tools' imports form no cycle, and tools/README.md lists every tool once, in one group. A benchmark is a
``tools/bench_*.py`` or a tool listed under the README's "Benchmarks"; imports count wherever they stand (module
top, functions), in both forms the tools and the tests use (``import harness``, ``from tools.harness import``)."""
from __future__ import annotations

import ast
import re
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[2] / "tools"


def tool_imports(path: Path, tools: set[str]) -> set[str]:
    """The modules of ``tools`` (names without ``.py``) that the file at ``path`` imports anywhere in it."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            dotted = [alias.name.split(".") for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            module = node.module.split(".")
            dotted = [module + [alias.name] for alias in node.names] if module == ["tools"] else [module]
        else:
            continue
        for parts in dotted:
            name = parts[1] if parts[0] == "tools" and len(parts) > 1 else parts[0]
            if name in tools:
                found.add(name)
    return found


def readme_groups(text: str) -> dict[str, list[str]]:
    """Each tool file (path under tools/) the README lists -> the group headings (``## ...``) it is listed under:
    the first ```tools/...``` of each bullet line names the tool."""
    groups: dict[str, list[str]] = {}
    heading = ""
    for line in text.splitlines():
        if line.startswith("## "):
            heading = line[3:].strip()
        match = re.match(r"- `tools/([^`]+)`", line)
        if match:
            groups.setdefault(match.group(1), []).append(heading)
    return groups


def cycle(graph: dict[str, set[str]]) -> list[str]:
    """One import cycle of ``graph`` (module -> modules it imports) as a path that ends where it starts, or []."""
    state: dict[str, str] = {}

    def visit(node: str, path: list[str]) -> list[str]:
        state[node] = "open"
        for other in sorted(graph[node]):
            if state.get(other) == "open":
                return path[path.index(other):] + [node, other] if other in path else [node, other]
            if other not in state:
                found = visit(other, path + [node])
                if found:
                    return found
        state[node] = "done"
        return []

    for start in sorted(graph):
        if start not in state:
            found = visit(start, [])
            if found:
                return found
    return []


def violations(folder: Path) -> list[str]:
    """Every break of the rules in ``folder`` (a tools folder with its README.md), one message each."""
    files = sorted(folder.glob("*.py"))
    tools = {path.stem for path in files}
    groups = readme_groups((folder / "README.md").read_text())
    benchmarks = {name for name in tools if name.startswith("bench_") or "Benchmarks" in groups.get(f"{name}.py", [])}
    graph = {path.stem: tool_imports(path, tools) - {path.stem} for path in files}
    found = []
    for path in files:
        listed = groups.get(path.name, [])
        if len(listed) != 1:
            found.append(f"{path.name} is listed {len(listed)} times in README.md (groups {listed})")
    for name in sorted(benchmarks):
        if "Benchmarks" not in groups.get(f"{name}.py", []):
            found.append(f"{name}.py is a benchmark not listed under Benchmarks")
        if "harness" not in graph[name]:
            found.append(f"{name}.py does not time with harness.py")
    for name in sorted(tools):
        for imported in sorted(graph[name] & benchmarks):
            found.append(f"{name}.py imports the benchmark {imported}.py")
    loop = cycle(graph)
    if loop:
        found.append("import cycle: " + " -> ".join(loop))
    return found


def test_tools_follow_the_import_rules() -> None:
    assert violations(TOOLS) == []


def test_every_rule_is_checked(tmp_path: Path) -> None:
    """A tools folder that breaks each rule once gets each break reported (the check can fail)."""
    sources = {
        "harness.py": "",
        "bench_a.py": "import harness\nfrom bench_b import run\n",  # a benchmark importing a benchmark
        "bench_b.py": "def run():\n    from tools.scenes import build\n",  # no harness; a lazy import
        "scenes.py": "import harness\n",
        "report.py": "def f():\n    import bench_a\n",  # a helper importing a benchmark
        "loop_x.py": "from tools import loop_y\n",
        "loop_y.py": "import loop_x\n",
        "unlisted.py": "",
    }
    for name, text in sources.items():
        (tmp_path / name).write_text(text)
    helpers = ["harness.py", "scenes.py", "report.py", "loop_x.py", "loop_y.py", "harness.py"]
    (tmp_path / "README.md").write_text("## Benchmarks\n\n- `tools/bench_a.py` - a\n\n## Helpers\n\n"
                                        + "".join(f"- `tools/{name}` - x\n" for name in helpers))
    assert sorted(violations(tmp_path)) == sorted([
        "bench_a.py imports the benchmark bench_b.py",
        "bench_b.py does not time with harness.py",
        "bench_b.py is a benchmark not listed under Benchmarks",
        "bench_b.py is listed 0 times in README.md (groups [])",
        "harness.py is listed 2 times in README.md (groups ['Helpers', 'Helpers'])",
        "report.py imports the benchmark bench_a.py",
        "unlisted.py is listed 0 times in README.md (groups [])",
        "import cycle: loop_x -> loop_y -> loop_x",
    ])
