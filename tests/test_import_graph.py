"""The package has no import cycles: the static graph of every ``import`` in hybridgen, function-level (lazy)
and ``if TYPE_CHECKING:`` imports included, has no strongly connected component; and the rooms of render/ keep
to their import rules (hybridgen/render/__init__.py, docs/architecture.md)."""
from __future__ import annotations

import ast
from pathlib import Path

import hybridgen

ROOT = Path(hybridgen.__file__).parent


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement of a module, at any depth: module level, in functions, under ``TYPE_CHECKING``."""
    return [node for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom))]


def import_graph() -> dict[str, set[str]]:
    """Module -> the hybridgen modules it imports anywhere in its code."""
    files = {_module_name(p): p for p in ROOT.rglob("*.py")}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in _imports(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            else:
                base = node.module or ""
                if node.level:
                    parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(parent + ([node.module] if node.module else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]
            graph[name].update(t for t in targets if t in files and t != name)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_cycle_finder_finds_a_planted_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_the_graph_sees_relative_lazy_and_type_checking_imports():
    graph = import_graph()
    assert "hybridgen.run.steps" in graph["hybridgen.run.pipeline"]  # from .steps import ... (top level)
    assert "hybridgen.sampling.registry" in graph["hybridgen.config.schema"]  # inside Param.validate
    assert "hybridgen.run.context" in graph["hybridgen.modules.base"]  # under if TYPE_CHECKING:
    assert "hybridgen.render.pathtrace.denoise" in graph["hybridgen.render.render_color"]  # from .pathtrace.denoise


def _edges(graph: dict[str, set[str]], source: str, target: str) -> list[str]:
    """The imports from modules under ``source`` into modules under ``target`` (package prefixes)."""
    def under(name: str, prefix: str) -> bool:
        return name == prefix or name.startswith(prefix + ".")
    return sorted(f"{m} -> {t}" for m, ts in graph.items() if under(m, source) for t in ts if under(t, target))


def test_raster_and_pathtrace_never_import_each_other():
    """Labels (GL) and color (Mitsuba) are separate rooms: what joins them lives at render/'s top."""
    graph = import_graph()
    assert _edges(graph, "hybridgen.render.raster", "hybridgen.render.pathtrace") == []
    assert _edges(graph, "hybridgen.render.pathtrace", "hybridgen.render.raster") == []
    assert _edges(graph, "hybridgen.render.render_color", "hybridgen.render.raster")  # the join uses both sides
    assert _edges(graph, "hybridgen.render.render_color", "hybridgen.render.pathtrace")


def test_render_imports_no_config_module_run_or_api_layer():
    """render/ sits below the config, module and run layers (and the BlenderProc API above them); the one
    exception is the notice channel, a leaf that config/ hosts."""
    graph = import_graph()
    upward = [edge for layer in ("config", "modules", "run", "cli", "bproc", "data")
              for edge in _edges(graph, "hybridgen.render", f"hybridgen.{layer}")
              if not edge.endswith("-> hybridgen.config.notices")]
    assert upward == [], "\n".join(upward)


def test_a_planted_cross_import_is_caught():
    """The rule check sees a lazy import planted in a raster module."""
    graph = import_graph()
    graph["hybridgen.render.raster.readback"] = graph["hybridgen.render.raster.readback"] | {
        "hybridgen.render.pathtrace.path_trace"}
    assert _edges(graph, "hybridgen.render.raster", "hybridgen.render.pathtrace") == [
        "hybridgen.render.raster.readback -> hybridgen.render.pathtrace.path_trace"]


def test_no_import_cycles():
    graph = import_graph()
    assert cycles(graph) == [], "\n".join(" <-> ".join(c) for c in cycles(graph))


def test_config_uses_sampling_but_sampling_never_imports_config():
    """Config values hold samplers (config.schema parses them), so sampling sits below config: the helpers both
    read (input paths, nested values) live in hybridgen.input_paths and hybridgen.nested, below both."""
    graph = import_graph()
    upward = sorted(f"{module} -> {target}" for module, targets in graph.items()
                    if module.startswith("hybridgen.sampling") for target in targets
                    if target.startswith("hybridgen.config"))
    assert upward == [], "\n".join(upward)
    assert any(t.startswith("hybridgen.sampling") for t in graph["hybridgen.config.schema"])  # the other way is used


# ------------------------------------------------------------------ what start-up and a labels-only run load

HEAVY = ("numpy", "h5py", "yaml", "packaging", "moderngl", "mitsuba", "drjit", "trimesh", "scipy", "PIL", "tqdm")
"""Packages ``import hybridgen`` and ``hybridgen --help`` must not load (each costs 10 ms to 1 s of start-up)."""

COLOR_ONLY = ("mitsuba", "drjit", "pyoidn", "hybridgen.render.pathtrace.path_trace", "hybridgen.render.render_color",
              "hybridgen.render.pathtrace.mitsuba_scene", "hybridgen.render.pathtrace.mitsuba_variant", "hybridgen.render.pathtrace.denoise")
"""What only a color (path-traced) run needs: a labels-only run imports none of it."""

LABELS_ONLY_CONFIG = """
global: {{all: {{output_dir: "<args:0>"}}}}
modules:
  - {{name: main.Initializer, config: {{seed: 1}}}}
  - {{name: loader.ObjLoader, config: {{path: "{mesh}", category_id: 2}}}}
  - name: camera.CameraLoader
    config:
      intrinsics: {{resolution_x: 32, resolution_y: 24}}
      cam_poses:
        - {{location: [0, -3, 1.5], rotation: {{format: look_at, value: [0, 0, 0]}}}}
  - {{name: renderer.SegMapRenderer, config: {{render_depth: true, render_normals: true, map_by: [class, instance]}}}}
  - {{name: writer.Hdf5Writer}}
"""


def _modules_after(code: str, env: dict[str, str] | None = None) -> set[str]:
    """The names in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    import json
    import os
    import subprocess
    import sys

    script = f"{code}\nimport json as _json, sys as _sys\nprint(_json.dumps(sorted(_sys.modules)))"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                          env={**os.environ, **(env or {})}, cwd=ROOT.parent)
    assert done.returncode == 0, done.stderr
    return set(json.loads(done.stdout.splitlines()[-1]))


def _loaded(modules: set[str], names: tuple[str, ...]) -> list[str]:
    return sorted(n for n in names if n in modules or any(m.startswith(n + ".") for m in modules))


def test_import_hybridgen_and_help_load_no_heavy_package():
    """The public names are imported on first use (hybridgen/__init__.py, PEP 562) and the command line
    parses its arguments before importing what a command needs."""
    assert _loaded(_modules_after("import hybridgen"), HEAVY) == []
    help_text = "from hybridgen.cli import build_parser\nbuild_parser().format_help()"
    assert _loaded(_modules_after(help_text), HEAVY) == []
    touched = _modules_after("import hybridgen\nhybridgen.Scene")  # a name still works, and loads what it needs
    assert "numpy" in touched and "hybridgen.scene.scene" in touched


def test_labels_only_run_loads_no_color_code_and_a_cached_mesh_no_trimesh(tmp_path):
    """A labels-only run never imports Mitsuba, Dr.Jit, the denoiser or the path tracer's modules; with its mesh
    in the cache (second run) it does not import trimesh or SciPy either, nor the physics package."""
    config = tmp_path / "labels.yaml"
    config.write_text(LABELS_ONLY_CONFIG.format(mesh=ROOT.parent / "configs/assets/crate.obj"))
    env = {"HYBRIDGEN_CACHE_DIR": str(tmp_path / "cache")}
    for run in ("cold", "warm"):
        code = (f"from hybridgen.cli import main\n"
                f"assert main(['run', '-q', {str(config)!r}, {str(tmp_path / run)!r}]) == 0")
        modules = _modules_after(code, env)
        assert (tmp_path / run / "data.hdf5").is_file()
        assert "hybridgen.render.raster.render_labels" in modules  # the labels were rendered in this process
        assert _loaded(modules, COLOR_ONLY) == [], run
    assert _loaded(modules, ("trimesh", "scipy", "hybridgen.physics")) == []
