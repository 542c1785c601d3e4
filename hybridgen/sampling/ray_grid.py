"""BlenderProc 2's camera checks on an ``n x n`` grid of rays spanning the image corner to corner
(``visible_objects``, ``scene_coverage_score``, ``perform_obstacle_in_view_check``).

BlenderProc casts ray ``(i, j)`` from the camera centre through the point ``i / (n - 1)`` of the way across the
image frame (its outer edges, not pixel centres) and ``j / (n - 1)`` of the way down. :func:`grid_intrinsics`
is the ``n x n``-pixel pinhole camera whose pixel centres are exactly those rays, so one raster draw of it is
that grid (hybridgen's :class:`~hybridgen.render.raster.raster_view.RasterView`), and :func:`grid_rays` gives
the rays themselves for a caster that casts one at a time. Distances are metres from the camera centre.
"""
from __future__ import annotations

import numbers
from typing import Any, Mapping

import numpy as np

from ..errors import InputError
from ..scene.intrinsics import Intrinsics

NEAR_M = 1e-3
FAR_M = 1e6
"""Clip range of the grid camera: BlenderProc's rays start at the camera centre and have no end."""


def grid_intrinsics(intr: Intrinsics, rays_per_side: int) -> Intrinsics:
    """The ``n x n`` camera whose pixel centre ``(i, j)`` looks through image point ``(-0.5 + W i / (n - 1),
    -0.5 + H j / (n - 1))`` of ``intr`` (pixel centres at integers, so -0.5 and W - 0.5 are the edges)."""
    n = int(rays_per_side)
    if n < 2:
        raise InputError(f"sqrt_number_of_rays must be at least 2 (the grid spans the image corner to corner), got {n}")
    K = np.eye(3)
    K[0, 0] = intr.K[0, 0] * (n - 1) / intr.width
    K[1, 1] = intr.K[1, 1] * (n - 1) / intr.height
    K[0, 2] = (intr.K[0, 2] + 0.5) * (n - 1) / intr.width
    K[1, 2] = (intr.K[1, 2] + 0.5) * (n - 1) / intr.height
    return Intrinsics(K, n, n, NEAR_M, FAR_M)


def grid_rays(intr: Intrinsics, rays_per_side: int, cam2world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), directions (n * n, 3)) of the grid in world coordinates for an OpenCV-axes ``cam2world``;
    the directions are not normalised (camera z = 1)."""
    pose = np.asarray(cam2world, dtype=np.float64)
    rays = grid_intrinsics(intr, rays_per_side).pixel_rays().reshape(-1, 3)
    return pose[:3, 3].copy(), rays @ pose[:3, :3].T


def _bounds(checks: Mapping[str, Any]) -> None:
    for operator in ("min", "max"):
        if operator in checks and not isinstance(checks[operator], numbers.Number):
            raise InputError(f"proximity_checks['{operator}'] must be a number, got {checks[operator]!r}")
    for operator in ("avg", "var"):
        if operator in checks:
            bounds = checks[operator]
            if not isinstance(bounds, Mapping) or "min" not in bounds or "max" not in bounds:
                raise InputError(f"proximity_checks['{operator}'] needs the interval {{'min': ..., 'max': ...}}")
            if not all(isinstance(bounds[k], numbers.Number) for k in ("min", "max")):
                raise InputError(f"proximity_checks['{operator}'] bounds must be numbers, got {dict(bounds)}")


def ray_range(checks: Mapping[str, Any]) -> float:
    """How far BlenderProc's obstacle check casts (m): without ``avg``/``var`` only as far as ``max`` + 1 m (or
    ``min``), a hit beyond that counting as no hit; unlimited with ``no_background``, ``avg`` or ``var``."""
    if checks.get("no_background") or "avg" in checks or "var" in checks:
        return float("inf")
    return float(checks["max"]) + 1.0 if "max" in checks else float(checks.get("min", float("inf")))


def obstacle_check_passes(distance: np.ndarray, hit: np.ndarray, checks: Mapping[str, Any]) -> bool:
    """BlenderProc's ``proximity_checks`` on one grid's hit distances (m; ``hit`` false: the ray hit nothing
    within :func:`ray_range`): every hit must be farther than ``min`` and nearer than ``max`` (strictly); the
    mean and variance of the distances over ALL rays (misses count as 0) strictly inside ``avg`` and ``var``;
    ``no_background``: every ray hits. No checks: the pose passes."""
    if not checks:
        return True
    _bounds(checks)
    distance = np.where(hit, np.asarray(distance, dtype=np.float64), 0.0).ravel()
    hits = distance[np.asarray(hit).ravel()]
    if checks.get("no_background") and hits.size < distance.size:
        return False
    if "min" in checks and np.any(hits <= checks["min"]):
        return False
    if "max" in checks and np.any(hits >= checks["max"]):
        return False
    mean = float(distance.sum()) / distance.size
    if "avg" in checks and not checks["avg"]["min"] < mean < checks["avg"]["max"]:
        return False
    if "var" in checks:
        variance = float((distance * distance).sum()) / distance.size - mean * mean
        if not checks["var"]["min"] < variance < checks["var"]["max"]:
            return False
    return True
