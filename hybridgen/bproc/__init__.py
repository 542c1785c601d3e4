"""BlenderProc 2's Python API (``import blenderproc as bproc``) over hybridgen's own Python API.

One module per BlenderProc area (``types``, ``loader``, ``object``, ``camera``, ``lighting``, ``world``,
``renderer``, ``writer``, ``material``, ``filter``, ``utility``, ``math``, ``sampler``, ``postprocessing``,
``constructor``) plus ``init``/``clean_up``. The scene is one process-wide session
(:mod:`hybridgen.bproc.session`), as Blender's is. ``hybridgen run main.py ARGS...`` runs a BlenderProc script
with ``import blenderproc`` resolving to this package; new scripts can ``import hybridgen.bproc as bproc``.
Functions of BlenderProc's API that hybridgen does not implement raise one line naming the call.
"""
from __future__ import annotations

from . import math, sampler, types

__all__ = ["math", "sampler", "types"]
