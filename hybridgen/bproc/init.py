"""``bproc.init()`` and ``bproc.clean_up()`` (BlenderProc's Initializer).

``init`` empties the session, sets BlenderProc 2.8's defaults (camera 512 x 512, fov 0.691111 rad, clip
0.1..1000 m; renderer: see :class:`~hybridgen.bproc.session.RendererSettings`; world grey 0.05) and, when the
environment variable ``BLENDER_PROC_RANDOM_SEED`` is set, seeds Python's ``random`` and NumPy's global
``np.random`` with it, exactly as BlenderProc does (``random.seed(s)``, ``np.random.seed(s)``), so a script's own
draws repeat.
"""
from __future__ import annotations

import os
import random

import numpy as np

from ..errors import InputError
from ..logs import LOGGER
from .blender_camera import BlenderCamera
from .session import SESSION, CameraState, RendererSettings, reset

SEED_ENV = "BLENDER_PROC_RANDOM_SEED"


def init(clean_up_scene: bool = True) -> None:
    """Start a BlenderProc session (once per script, as in BlenderProc)."""
    if SESSION.initialized:
        raise InputError("BlenderProc has already been initialized via bproc.init(), this should not be done twice; "
                         "use bproc.clean_up() to empty the scene")
    if clean_up_scene:
        clean_up(clean_up_camera=True)
    SESSION.renderer = RendererSettings()
    SESSION.camera = CameraState(pose=SESSION.camera.pose)  # BlenderProc's default camera, stereo off
    seed = os.environ.get(SEED_ENV)
    if seed:
        try:
            value = int(seed)
        except ValueError:
            raise InputError(f"{SEED_ENV} must be an integer, got {seed!r}") from None
        LOGGER.info("Got random seed: %s", value)
        random.seed(value)
        np.random.seed(value)
    SESSION.initialized = True


def clean_up(clean_up_camera: bool = False) -> None:
    """Remove every object, light, material and camera pose and reset the world; renderer settings stay.
    ``clean_up_camera``: the camera's own parameters (lens, clip range) go back to Blender's defaults too."""
    for entity in list(SESSION.entities):
        entity._invalidate()
    for material in list(SESSION.materials):
        material._invalidate()
    camera = BlenderCamera() if clean_up_camera else SESSION.camera.blender
    reset(keep_initialized=SESSION.initialized)
    SESSION.camera.blender = camera
