"""hybridgen: synthetic training data - path-traced color plus exact rasterized labels.

Python API (every YAML module is a thin layer over it)::

    import hybridgen as hg
    scene = hg.Scene()
    for obj in hg.load_objects("duck.obj", name="duck", category_id=3):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.69, 640, 480)
    scene.camera.add_keypoint(hg.look_at([2, -2, 1.5], [0, 0, 0]))
    writer = hg.Hdf5SingleFileWriter("out/data.hdf5")
    hg.render_labels(scene, [writer], hg.LabelRequest(map_by=["class", "instance"]))
    writer.finalize({"object_states": [o.state() for o in scene.objects]})

The names are imported on first use (PEP 562), so ``import hybridgen`` and the command line's start do not
pay for NumPy, h5py, moderngl or Mitsuba until a name that needs them is touched; ``from hybridgen import X``
and ``hybridgen.X`` work as usual.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any, Sequence

from ._version import __version__
from .errors import ConfigError, HybridgenError, InputError, SystemSetupError

if TYPE_CHECKING:  # what static analysers see; at run time the same names come from __getattr__
    import numpy as np

    from .io.hdf5_single import Hdf5SingleFileWriter
    from .io.memory_sink import MemorySink
    from .io.mesh_cache import load_objects_cached as load_objects
    from .render.pathtrace.path_trace import PathTraceSettings
    from .render.raster.label_request import LabelRequest
    from .render.raster.raster_view import RasterView
    from .render.raster.render_labels import render_labels
    from .render.render_color import render_color
    from .run.pipeline import run_config
    from .scene import Camera, Intrinsics, Light, Material, MeshObject, Scene, World
    from .scene.frames import blender_to_opencv, make_pose, object_pose, opencv_to_blender
    from .scene.primitives import make_primitive

_LAZY = {
    "Hdf5SingleFileWriter": ".io.hdf5_single", "MemorySink": ".io.memory_sink",
    "load_objects": ".io.mesh_cache:load_objects_cached",
    "LabelRequest": ".render.raster.label_request", "PathTraceSettings": ".render.pathtrace.path_trace",
    "RasterView": ".render.raster.raster_view", "render_color": ".render.render_color",
    "render_labels": ".render.raster.render_labels", "run_config": ".run.pipeline",
    "Camera": ".scene", "Intrinsics": ".scene", "Light": ".scene", "Material": ".scene", "MeshObject": ".scene",
    "Scene": ".scene", "World": ".scene", "blender_to_opencv": ".scene.frames", "make_pose": ".scene.frames",
    "object_pose": ".scene.frames", "opencv_to_blender": ".scene.frames", "make_primitive": ".scene.primitives",
}
"""Public name -> the module that defines it (relative to this package), imported when the name is first used;
``module:attribute`` where the module's name for it differs (``load_objects`` is the cached loader, so a
script's second run reads its meshes without importing trimesh: :mod:`hybridgen.io.mesh_cache`)."""


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'hybridgen' has no attribute {name!r}")
    module, _, attribute = module.partition(":")
    value = getattr(importlib.import_module(module, __name__), attribute or name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


def look_at(location: Sequence[float], target: Sequence[float], inplane_rot: float = 0.0) -> "np.ndarray":
    """OpenCV-axes 4x4 cam2world of a camera at ``location`` looking at ``target`` (metres, world Z up)."""
    from .scene.frames import blender_to_opencv, look_at_blender, make_pose

    return blender_to_opencv(make_pose(look_at_blender(location, target, inplane_rot), location))


__all__ = [
    "__version__", "Camera", "ConfigError", "Hdf5SingleFileWriter", "HybridgenError", "InputError", "Intrinsics",
    "LabelRequest", "Light", "Material", "MemorySink", "MeshObject", "PathTraceSettings", "RasterView", "Scene", "SystemSetupError", "World",
    "blender_to_opencv", "load_objects", "look_at", "make_pose", "make_primitive", "object_pose", "opencv_to_blender",
    "render_color", "render_labels", "run_config",
]
