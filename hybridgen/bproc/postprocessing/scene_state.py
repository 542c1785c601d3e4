"""What ``bproc.postprocessing`` reads from the current scene when a script does not pass it, as BlenderProc
reads it from Blender's scene: the camera's K matrix, its stereo baseline and the distance pass's range.

Each is looked up on first use (``hybridgen.bproc.camera`` and :data:`hybridgen.bproc.session.SESSION` are
imported lazily), so these functions also work on explicit values without a session.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

BLENDER_MIST_END = 30.0
"""Blender's default mist range end (start 5 m + depth 25 m): ``stereo_global_matching``'s ``depth_max`` when
no antialiased distance output set the range."""

DEFAULT_DISTANCE_MAX = 10000.0
"""BlenderProc's ``antialiasing_distance_max`` default (m), the mist range an antialiased distance output sets."""


def camera_K(K: Optional[Any] = None) -> np.ndarray:  # noqa: N802, N803 - K is the matrix's name
    """``K`` as a 3x3 float array, or when None the current camera's (``bproc.camera.get_intrinsics_as_K_matrix``,
    pixels, principal point in pixel-centre coordinates)."""
    if K is None:
        try:
            from ..camera import get_intrinsics_as_K_matrix
        except ImportError as exc:
            raise RuntimeError("bproc.postprocessing needs the camera's intrinsics: hybridgen.bproc.camera is not "
                               "available, pass K= explicitly") from exc
        K = get_intrinsics_as_K_matrix()
    matrix = np.asarray(K, dtype=np.float64)
    if matrix.shape != (3, 3):
        raise ValueError(f"K must be a 3x3 intrinsics matrix, got shape {matrix.shape}")
    return matrix


def stereo_baseline() -> float:
    """The camera's stereo interocular distance (m; Blender's default 0.065 until
    ``bproc.camera.set_stereo_parameters`` changes it)."""
    from ..session import SESSION

    return float(SESSION.camera.interocular_distance)


def distance_range_end() -> float:
    """Where the distance pass's range ends (m), Blender's ``mist_settings.start + depth``: the
    ``antialiasing_distance_max`` of an antialiased distance (or depth) output (``hybridgen.bproc.renderer``
    keeps it as the output's ``distance_max``), else Blender's default 30."""
    from ..session import SESSION

    for kind in ("distance", "depth"):
        options = SESSION.renderer.outputs.get(kind) or {}
        if options.get("antialiasing"):
            value = options.get("distance_max")
            return DEFAULT_DISTANCE_MAX if value is None else float(value)
    return BLENDER_MIST_END
