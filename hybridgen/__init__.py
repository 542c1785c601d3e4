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
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ._version import __version__
from .errors import ConfigError, HybridgenError, InputError, SystemSetupError
from .io.hdf5_single import Hdf5SingleFileWriter
from .io.memory_sink import MemorySink
from .io.mesh_loader import load_objects
from .render.label_request import LabelRequest
from .render.path_trace import PathTraceSettings
from .render.raster import RasterView
from .render.render_color import render_color
from .render.render_labels import render_labels
from .run.pipeline import run_config
from .scene import Camera, Intrinsics, Light, Material, MeshObject, Scene, World
from .scene.frames import blender_to_opencv, look_at_blender, make_pose, object_pose, opencv_to_blender
from .scene.primitives import make_primitive


def look_at(location: Sequence[float], target: Sequence[float], inplane_rot: float = 0.0) -> np.ndarray:
    """OpenCV-axes 4x4 cam2world of a camera at ``location`` looking at ``target`` (metres, world Z up)."""
    return blender_to_opencv(make_pose(look_at_blender(location, target, inplane_rot), location))


__all__ = [
    "__version__", "Camera", "ConfigError", "Hdf5SingleFileWriter", "HybridgenError", "InputError", "Intrinsics",
    "LabelRequest", "Light", "Material", "MemorySink", "MeshObject", "PathTraceSettings", "RasterView", "Scene", "SystemSetupError", "World",
    "blender_to_opencv", "load_objects", "look_at", "make_pose", "make_primitive", "object_pose", "opencv_to_blender",
    "render_color", "render_labels", "run_config",
]
