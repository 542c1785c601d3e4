"""BlenderProc 2.8's own sampler and post-processing functions, run outside Blender as references.

The ``blenderproc`` package (a test extra) is installed, but importing it outside Blender stops the process,
and its modules import ``bpy``/``mathutils``. :func:`load` executes one of its source files by path with
small stand-ins for those imports, so a test can call BlenderProc's function and compare it with
hybridgen's. The ``mathutils`` stand-in computes rotations with SciPy; tests compare rotations through
matrices, never Blender's own Euler choice (that is tested against hand-computed cases). Nothing of
BlenderProc's code is copied here: it is run from the installed package.
"""
from __future__ import annotations

import importlib.util
import sys
import types
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest
from scipy.spatial.transform import Rotation


def _package_root() -> Path:
    spec = importlib.util.find_spec("blenderproc")  # finds the package without running its __init__
    if spec is None or not spec.submodule_search_locations:
        pytest.skip("the blenderproc package (test extra) is not installed")
    return Path(list(spec.submodule_search_locations)[0])


class _Matrix:
    """``mathutils.Matrix`` stand-in: 3x3 rotations composed with ``@=``."""

    def __init__(self, values: Any) -> None:
        self.values = np.asarray(values, dtype=np.float64)

    @staticmethod
    def Identity(size: int) -> "_Matrix":  # noqa: N802 - mathutils' name
        return _Matrix(np.eye(size))

    @staticmethod
    def Rotation(angle: float, size: int, axis: str) -> "_Matrix":  # noqa: N802 - mathutils' name
        return _Matrix(Rotation.from_euler(axis.lower(), angle).as_matrix())

    def __matmul__(self, other: "_Matrix") -> "_Matrix":
        return _Matrix(self.values @ other.values)

    def to_euler(self) -> np.ndarray:
        return Rotation.from_matrix(self.values).as_euler("xyz")

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        return self.values if dtype is None else self.values.astype(dtype)


def _mathutils() -> types.ModuleType:
    module = types.ModuleType("mathutils")
    module.Vector = list  # type hints only
    module.Matrix = _Matrix
    module.Euler = lambda angles, order="XYZ": types.SimpleNamespace(
        to_matrix=lambda: _Matrix(Rotation.from_euler(order.lower(), np.asarray(angles, float)).as_matrix()))
    module.Quaternion = lambda wxyz: types.SimpleNamespace(
        to_euler=lambda: Rotation.from_quat(np.roll(np.asarray(wxyz, float), -1)).as_euler("xyz"))
    return module


def _stub(name: str, **attributes: Any) -> types.ModuleType:
    module = types.ModuleType(name)
    module.__path__ = []  # a package, so that submodules can be looked up under it
    module.__dict__.update(attributes)
    return module


def load(relative: str, extra: dict[str, types.ModuleType] | None = None) -> types.ModuleType:
    """Execute ``blenderproc/<relative>`` of the installed package with stand-ins for Blender's modules
    (and ``extra`` modules, e.g. BlenderProc modules it imports) and return it as a module."""
    path = _package_root() / relative
    if not path.exists():
        pytest.skip(f"the installed blenderproc has no {relative}")
    stubs = {"bpy": _stub("bpy"), "mathutils": _mathutils(), "blenderproc": _stub("blenderproc"),
             "blenderproc.python": _stub("blenderproc.python")}
    stubs.update(extra or {})
    saved = {name: sys.modules.get(name) for name in stubs}
    sys.modules.update(stubs)
    try:
        spec = importlib.util.spec_from_file_location(f"_blenderproc_reference_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        for name, previous in saved.items():
            if previous is None:
                sys.modules.pop(name, None)
            else:
                sys.modules[name] = previous
    return module


def sampler(name: str) -> types.ModuleType:
    """BlenderProc's ``blenderproc/python/sampler/<name>.py`` (PartSphere gets BlenderProc's own Sphere)."""
    extra = {"blenderproc.python.sampler": _stub("blenderproc.python.sampler"),
             "blenderproc.python.types": _stub("blenderproc.python.types"),
             "blenderproc.python.types.MeshObjectUtility": _stub("MeshObjectUtility", MeshObject=object)}
    if name == "PartSphere":
        extra["blenderproc.python.sampler.Sphere"] = sampler("Sphere")
    return load(f"python/sampler/{name}.py", extra)


def postprocessing(intrinsics: Callable[[], np.ndarray], cv2: types.ModuleType | None = None) -> types.ModuleType:
    """BlenderProc's ``PostProcessingUtility`` whose camera returns ``intrinsics()`` as K (and ``cv2``, a
    stand-in that fails when called, unless the real one is given)."""
    camera = _stub("blenderproc.python.camera.CameraUtility", get_intrinsics_as_K_matrix=intrinsics)
    extra = {"cv2": cv2 or _stub("cv2"), "blenderproc.python.camera": _stub("blenderproc.python.camera",
                                                                            CameraUtility=camera),
             "blenderproc.python.camera.CameraUtility": camera,
             "blenderproc.python.utility": _stub("blenderproc.python.utility"),
             "blenderproc.python.utility.BlenderUtility": _stub("BlenderUtility",
                                                                get_all_blender_mesh_objects=list)}
    return load("python/postprocessing/PostProcessingUtility.py", extra)
