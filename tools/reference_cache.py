"""On-disk cache of the quality benchmark's converged references (tools/color_quality.py), keyed by content.

A 4096-spp reference costs minutes per scene (Cycles: several), and neither engine's reference changes unless
what defines it changes, so each is rendered once and found again by a key that names exactly that:

- Cycles: the exported scene's content (:func:`scene_digest`), mode, spp, seed, resolution, the ``bpy``
  version, and the code of tools/cycles_render.py (which builds the Blender scene from the export);
- hybridgen: the same scene content, spp, seed, clamp and lobe settings, resolution, the Mitsuba and Dr.Jit
  versions, and the code of every hybridgen module the reference estimator imports (:func:`estimator_digest`:
  ``render.path_trace`` and ``render.tonemap`` with their imports, followed statically), so a change to the
  renderer re-renders it and a change elsewhere (raster labels, writers) does not.

Code is hashed as its syntax tree without docstrings (:func:`code_digest`, attribute docstrings under constants
included): comments and docstrings can change without invalidating anything. An entry is
``<kind>-<scene>-<W>x<H>-<spp>spp-<digest>.png`` (8-bit sRGB, the image PSNR is computed on) with a ``.json`` beside it
holding the key and how it was made. Entries are written under a temporary name and renamed, so concurrent benchmark
runs never read half a file.

Where: ``$HYBRIDGEN_BENCH_CACHE`` or ``~/.cache/hybridgen/bench_color``; ``off`` (or ``--reference-cache off``)
disables the cache (everything is rendered again).
"""
from __future__ import annotations

import ast
import hashlib
import json
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DEFAULT_ROOT = Path("~/.cache/hybridgen/bench_color")
ESTIMATOR_MODULES = ("hybridgen.render.pathtrace.path_trace", "hybridgen.render.tonemap")
"""Where hybridgen's reference image is made (PathTraceView) and encoded (to_srgb8)."""


def cache_root(setting: str | None = None) -> Path | None:
    """The cache folder: ``setting`` (a path, or ``off``), else ``$HYBRIDGEN_BENCH_CACHE``, else the default;
    None when disabled."""
    value = setting if setting is not None else os.environ.get("HYBRIDGEN_BENCH_CACHE", str(DEFAULT_ROOT))
    return None if value.strip().lower() in ("off", "none", "") else Path(value).expanduser()


# ----------------------------------------------------------------------------------------- digests
def _sha(text: str | bytes) -> str:
    return hashlib.sha256(text.encode() if isinstance(text, str) else text).hexdigest()


def _is_bare_string(statement: ast.stmt) -> bool:
    """Whether ``statement`` is a string on its own: a docstring, or an attribute docstring after an assignment."""
    return (isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant)
            and isinstance(statement.value.value, str))


def code_digest(path: Path) -> str:
    """SHA-256 of a Python file's syntax tree without its bare strings - the docstrings of modules, classes and
    functions and those written under constants and attributes (comments are not in the tree)."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        for field in ("body", "orelse", "finalbody"):
            block = getattr(node, field, None)
            if isinstance(block, list):
                kept = [s for s in block if not _is_bare_string(s)]
                if len(kept) < len(block):
                    setattr(node, field, kept or [ast.Pass()])
    return _sha(ast.dump(tree))


def _module_file(name: str, root: Path) -> Path | None:
    """The source file of module ``name`` (dotted) under ``root`` (the folder holding the package)."""
    base = root.joinpath(*name.split("."))
    for candidate in (base / "__init__.py", base.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def _runtime_nodes(tree: ast.AST) -> list[ast.AST]:
    """Every node of ``tree`` except those under ``if TYPE_CHECKING:`` (its ``else`` branch is kept)."""
    nodes, pending = [], [tree]
    while pending:
        node = pending.pop()
        nodes.append(node)
        test = getattr(node, "test", None)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in (getattr(test, "id", None), getattr(test, "attr", None)):
            pending.extend(node.orelse)
        else:
            pending.extend(ast.iter_child_nodes(node))
    return nodes


def _imported_names(path: Path, name: str) -> set[str]:
    """Absolute names of everything ``path`` (module ``name``) imports anywhere in its code but type-checking
    blocks, including ``from package import submodule`` forms (names that are not modules are dropped by the
    caller)."""
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    names: set[str] = set()
    for node in _runtime_nodes(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            anchor = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join([*anchor, *([node.module] if node.module else [])])
            names.add(module)
            names.update(f"{module}.{alias.name}" for alias in node.names)
    return names


def module_closure(start: Iterable[str], root: Path = REPO, package: str = "hybridgen") -> dict[str, Path]:
    """``start``'s modules and every ``package`` module they import, transitively (static, lazy imports
    included): module name -> source file."""
    found: dict[str, Path] = {}
    pending = list(start)
    while pending:
        name = pending.pop()
        path = _module_file(name, root) if name not in found else None
        if path is None:
            continue
        found[name] = path
        pending.extend(n for n in _imported_names(path, name) if n.split(".")[0] == package)
        parent = name.rpartition(".")[0]
        if parent:  # a package's __init__ runs before its modules
            pending.append(parent)
    return found


def estimator_digest() -> str:
    """Digest of the code of hybridgen's reference estimator (:data:`ESTIMATOR_MODULES` and their imports)."""
    files = module_closure(ESTIMATOR_MODULES)
    return _sha("".join(f"{name}:{code_digest(files[name])}\n" for name in sorted(files)))


def scene_digest(npz: Path) -> str:
    """Digest of a scene exported for Cycles (tools/cycles_export.py): every array, and the metadata
    with the HDRI's path replaced by its bytes' digest and the worker's thread count and default spp left
    out (neither changes a reference image)."""
    data = np.load(npz, allow_pickle=False)
    parts = []
    for key in sorted(data.files):
        if key == "meta":
            meta = json.loads(str(data["meta"]))
            meta.pop("threads", None)
            meta.pop("spp", None)
            if meta.get("hdri"):
                meta["hdri"]["path"] = _sha(Path(meta["hdri"]["path"]).read_bytes())
            parts.append(_sha(json.dumps(meta, sort_keys=True)))
        else:
            array = np.ascontiguousarray(data[key])
            parts.append(f"{key}:{array.dtype.str}:{array.shape}:{_sha(array.tobytes())}")
    return _sha("\n".join(parts))


# ------------------------------------------------------------------------------------------- cache
class ReferenceCache:
    """Reference images (8-bit sRGB H x W x 3) on disk under ``root`` (None: a cache that keeps nothing)."""

    def __init__(self, root: Path | None) -> None:
        self.root = root

    def _paths(self, kind: str, key: dict[str, Any]) -> tuple[Path, Path] | None:
        if self.root is None:
            return None
        digest = _sha(json.dumps(key, sort_keys=True))[:16]
        stem = f"{kind}-{key['scene']}-{key['resolution']}-{key['spp']}spp-{digest}"
        return self.root / f"{stem}.png", self.root / f"{stem}.json"

    def load(self, kind: str, key: dict[str, Any]) -> tuple[np.ndarray, dict[str, Any]] | None:
        """The stored image and its record (key, seconds, created), or None if absent or disabled."""
        from PIL import Image

        paths = self._paths(kind, key)
        if paths is None or not (paths[0].is_file() and paths[1].is_file()):
            return None
        return np.asarray(Image.open(paths[0]).convert("RGB")), json.loads(paths[1].read_text())

    def store(self, kind: str, key: dict[str, Any], image: np.ndarray, info: dict[str, Any]) -> None:
        """Writes the image and its record (``info`` plus the key and the time), each atomically."""
        from PIL import Image

        paths = self._paths(kind, key)
        if paths is None:
            return
        self.root.mkdir(parents=True, exist_ok=True)  # type: ignore[union-attr]
        record = {"kind": kind, "key": key, "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), **info}
        for path, write in ((paths[0], lambda p: Image.fromarray(image).save(p, format="PNG")),
                            (paths[1], lambda p: p.write_text(json.dumps(record, indent=1)))):
            partial = path.with_name(f".{path.name}.{os.getpid()}.incomplete")
            write(partial)
            os.replace(partial, path)

    def fetch(self, kind: str, key: dict[str, Any],
              render: Callable[[], tuple[np.ndarray, dict[str, Any]]]) -> tuple[np.ndarray, dict[str, Any]]:
        """The cached image and record for ``key``, or ``render()``'s (image, info), stored first; the record
        says ``"cached": True`` when it came from disk."""
        found = self.load(kind, key)
        if found is not None:
            return found[0], {**found[1], "cached": True}
        image, info = render()
        self.store(kind, key, image, info)
        return image, {**info, "cached": False}
