"""BlenderProc 2's Python API (``import blenderproc as bproc``) over hybridgen's own Python API.

One module per BlenderProc area (``types``, ``loader``, ``object``, ``camera``, ``lighting``, ``world``,
``renderer``, ``writer``, ``material``, ``filter``, ``utility``, ``math``, ``sampler``, ``postprocessing``,
``constructor``) plus ``init``/``clean_up``. The scene is one process-wide session
(:mod:`hybridgen.bproc.session`), as Blender's is. ``hybridgen run main.py ARGS...`` runs a BlenderProc script
with ``import blenderproc`` resolving to this package (:mod:`hybridgen.bproc.script`); new scripts can
``import hybridgen.bproc as bproc``. Functions of BlenderProc's API that hybridgen does not implement raise one
line naming the call (:mod:`hybridgen.bproc.types.unsupported`).

May import: everything of hybridgen below it (scene, sampling, physics, io, modules, render's entry points and
shared helpers); never the raster or path-tracing internals (docs/architecture.md).
"""
from __future__ import annotations

import importlib.util

from . import (camera, constructor, filter, lighting, loader, material, math, object, renderer, sampler, types,
               utility, world, writer)
from .init import clean_up, init

__all__ = ["camera", "clean_up", "constructor", "filter", "init", "lighting", "loader", "material", "math", "object",
           "renderer", "sampler", "types", "utility", "world", "writer"]

if importlib.util.find_spec(f"{__name__}.postprocessing") is not None:  # written beside this layer
    from . import postprocessing  # noqa: F401

    __all__.append("postprocessing")
