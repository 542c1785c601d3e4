"""Running a BlenderProc 2 script (``hybridgen run main.py ARGS...``) the way ``blenderproc run main.py ARGS...``
does, on hybridgen's ``bproc`` layer.

For the script's run:

- ``import blenderproc`` (and ``blenderproc.<area>``) is this package, ``hybridgen.bproc``, through a meta-path
  finder placed first - also when the real ``blenderproc`` package is installed or already imported.
  BlenderProc's internal modules (``blenderproc.python.utility.Utility``, ...) are
  :mod:`hybridgen.bproc.internal_modules`; a module path neither knows raises one line naming the
  module. ``import bpy`` is :mod:`hybridgen.bproc.bpy_standin`.
- ``sys.argv`` is ``[script, ARGS...]`` and the script's folder is first on ``sys.path``, as for
  ``python main.py``; the working directory is unchanged, so relative paths resolve as under BlenderProc.
- The session starts empty; ``bproc.init()`` seeds ``random`` and ``np.random`` from ``BLENDER_PROC_RANDOM_SEED``
  as BlenderProc does.
- hybridgen's errors (:class:`~hybridgen.errors.HybridgenError`, e.g. a call that is not supported) propagate as
  one line (the CLI's exit status 2); any other exception is the script's own: its traceback is printed without
  hybridgen's runner frames and the process exits with status 1.

Everything is restored afterwards (``sys.modules``, ``sys.meta_path``, ``sys.argv``, ``sys.path``).
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import os
import runpy
import sys
import time
import traceback
from types import ModuleType
from typing import Any, Sequence

from ..errors import HybridgenError, InputError
from .internal_modules import INTERNAL_MODULES, PACKAGES, ROOT, internal_module
from .session import SESSION, Session

PACKAGE = __name__.rpartition(".")[0]
ALIASES = {"blenderproc": PACKAGE, "bpy": f"{PACKAGE}.bpy_standin", "mathutils": f"{PACKAGE}.mathutils_standin"}


class _AliasLoader(importlib.abc.Loader):
    """Loads an aliased name as the hybridgen module it stands for (the same module object)."""

    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(self.target)

    def exec_module(self, module: ModuleType) -> None:
        """The target module ran when it was imported."""


class _InternalLoader(importlib.abc.Loader):
    """Builds a BlenderProc internal module (``blenderproc.python...``) over hybridgen.bproc."""

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return internal_module(spec.name, PACKAGE)

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run: the module looks its names up when they are read."""


class BlenderProcFinder(importlib.abc.MetaPathFinder):
    """``blenderproc[.area]`` -> ``hybridgen.bproc[.area]``, ``bpy`` -> the bpy stand-in."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        head, _, rest = fullname.partition(".")
        if head not in ALIASES:
            return None
        if fullname in INTERNAL_MODULES or fullname in PACKAGES:
            return importlib.machinery.ModuleSpec(fullname, _InternalLoader(), is_package=fullname in PACKAGES)
        module = ALIASES[head] + (f".{rest}" if rest else "")
        if head == "bpy" and rest or not _exists(module):
            raise InputError(f"import {fullname}: the module is not supported by hybridgen yet (hybridgen's "
                             f"blenderproc has the bproc.<area> API modules and {ROOT}'s modules behind them)")
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(module), is_package=not rest)


def _exists(module: str) -> bool:
    """Whether the hybridgen module ``module`` exists (False also when a package on its way does not)."""
    try:
        return importlib.util.find_spec(module) is not None
    except ModuleNotFoundError:
        return False


def _script_traceback(exc: BaseException, script: str) -> str:
    """The traceback from the script's first frame on (hybridgen's runner frames left out)."""
    frames = traceback.extract_tb(exc.__traceback__)
    start = next((i for i, frame in enumerate(frames) if os.path.abspath(frame.filename) == script), 0)
    lines = ["Traceback (most recent call last):\n", *traceback.format_list(frames[start:])]
    return "".join(lines + traceback.format_exception_only(type(exc), exc))


def run_script(path: str, args: Sequence[str]) -> float:
    """Run the BlenderProc script ``path`` with ``args``; returns its wall time (s). See the module doc."""
    script = os.path.abspath(path)
    if not os.path.isfile(script):
        raise InputError(f"script '{path}' does not exist")
    saved_modules = {name: module for name, module in sys.modules.items() if name.partition(".")[0] in ALIASES}
    saved_argv, saved_path = list(sys.argv), list(sys.path)
    finder = BlenderProcFinder()
    for name in saved_modules:
        del sys.modules[name]
    sys.meta_path.insert(0, finder)
    sys.argv = [path, *args]
    sys.path.insert(0, os.path.dirname(script))
    SESSION.__dict__.update(Session().__dict__)
    started = time.perf_counter()
    try:
        runpy.run_path(script, run_name="__main__")
    except (HybridgenError, SystemExit, KeyboardInterrupt):
        raise
    except Exception as exc:  # the script's own error (or a bug below it): its traceback, exit status 1
        sys.stderr.write(_script_traceback(exc, script))
        sys.stderr.flush()
        raise SystemExit(1) from None
    finally:
        sys.meta_path.remove(finder)
        for name in [n for n in sys.modules if n.partition(".")[0] in ALIASES]:
            del sys.modules[name]
        sys.modules.update(saved_modules)
        sys.argv, sys.path[:] = saved_argv, saved_path
    return time.perf_counter() - started
