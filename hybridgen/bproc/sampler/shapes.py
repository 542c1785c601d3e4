"""Point samplers of ``bproc.sampler`` on simple shapes: ``sphere``, ``part_sphere``, ``shell`` and ``disk``.

Every draw comes from NumPy's global random state (``np.random``), in the order BlenderProc 2.8 draws, so a
script seeded as under BlenderProc (``BLENDER_PROC_RANDOM_SEED``) gets the same points. Points are world
coordinates in metres, returned as ``(3,)`` float64 arrays; angles named ``*_angle``, ``elevation_*`` and
``azimuth_*`` are degrees, ``rotation`` is Blender ``XYZ`` Euler angles in radians.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ..math import build_transformation_mat

__all__ = ["disk", "part_sphere", "shell", "sphere"]


def _normal_draws(size: int) -> np.ndarray:
    """``size`` standard normal draws, a direction (an all-zero draw becomes ``(1e-5, 0, ...)``, as in
    BlenderProc)."""
    direction = np.random.normal(loc=0.0, scale=1.0, size=size)
    if not direction.any():
        direction[0] = 1e-5
    return direction


def _scaled(direction: np.ndarray, magnitude: float) -> np.ndarray:
    """``direction`` scaled to length ``magnitude`` (multiplied, then divided by the norm, as BlenderProc)."""
    return magnitude * direction / np.sqrt(direction.dot(direction))


def sphere(center: Any, radius: float, mode: str) -> np.ndarray:
    """A point on the sphere (``mode="SURFACE"``) or in the ball (``"INTERIOR"``) of ``radius`` metres around
    ``center``, uniform by area or by volume.

    Draws three normal numbers for the direction, then (``INTERIOR`` only) one uniform number ``u`` for the
    radius ``radius * cbrt(u)``.
    """
    direction = _normal_draws(3)
    if mode == "SURFACE":
        magnitude = radius
    elif mode == "INTERIOR":
        magnitude = radius * np.cbrt(np.random.uniform())
    else:
        raise ValueError(f"bproc.sampler.sphere: unknown mode {mode!r} (SURFACE or INTERIOR)")
    return _scaled(direction, magnitude) + np.array(center)


def part_sphere(center: Any, radius: float, mode: str, dist_above_center: float = 0.0,
                part_sphere_dir_vector: Optional[Any] = None) -> np.ndarray:
    """A :func:`sphere` point whose offset from ``center`` along ``part_sphere_dir_vector`` (default +Z,
    normalised in float32 as BlenderProc does) exceeds ``dist_above_center`` metres: the cap of the sphere
    (or ball) cut by a plane. Draws :func:`sphere` points until one is in the cap.
    """
    if part_sphere_dir_vector is None:
        cut_normal = np.array([0.0, 0.0, 1.0], dtype=np.float32)
    else:
        cut_normal = np.array(part_sphere_dir_vector).astype(np.float32)
    cut_normal /= np.linalg.norm(cut_normal)
    if dist_above_center >= radius:
        raise ValueError(f"bproc.sampler.part_sphere: dist_above_center ({dist_above_center}) must be smaller "
                         f"than the radius ({radius})")
    origin = np.array(center)
    while True:
        location = sphere(center, radius, mode)
        if (location - origin).dot(cut_normal) > dist_above_center:
            return location


def _check_shell(elevation_min: float, elevation_max: float, azimuth_min: float, azimuth_max: float) -> None:
    """BlenderProc's checks of shell's angles (degrees); like BlenderProc it leaves ``elevation_max``'s
    range unchecked, so a script it runs runs here too."""
    if not (-180 <= azimuth_min <= 180 and -180 <= azimuth_max <= 180):
        raise ValueError(f"bproc.sampler.shell: azimuth_min ({azimuth_min}) and azimuth_max ({azimuth_max}) must "
                         "be in [-180, 180] degrees")
    if not -90 <= elevation_min <= 90:
        raise ValueError(f"bproc.sampler.shell: elevation_min ({elevation_min}) must be in [-90, 90] degrees")
    if not (azimuth_min < azimuth_max and elevation_min < elevation_max):
        raise ValueError("bproc.sampler.shell: azimuth_min and elevation_min must be smaller than azimuth_max "
                         "and elevation_max")


def shell(center: Any, radius_min: float, radius_max: float, elevation_min: float = -90,
          elevation_max: float = 90, azimuth_min: float = -180, azimuth_max: float = 180,
          uniform_volume: bool = False) -> np.ndarray:
    """A point between the spheres of ``radius_min`` and ``radius_max`` metres around ``center``, in the
    elevation band (degrees above the XY plane) and azimuth range (degrees from +X towards +Y).

    By default the elevation, the azimuth and the radius are each uniform (so points crowd towards the
    poles and the inner sphere), drawn in that order. With ``uniform_volume`` the radius is drawn first as
    ``radius_min + (radius_max - radius_min) * cbrt(u)``, then normal triples until their direction lies
    strictly inside both angle ranges (BlenderProc's rejection loop).
    """
    _check_shell(elevation_min, elevation_max, azimuth_min, azimuth_max)
    if uniform_volume:
        radius = radius_min + (radius_max - radius_min) * np.cbrt(np.random.rand())
        low_el, high_el = np.deg2rad(elevation_min), np.deg2rad(elevation_max)
        low_az, high_az = np.deg2rad(azimuth_min), np.deg2rad(azimuth_max)
        while True:
            direction = np.random.randn(3)
            direction /= np.linalg.norm(direction)
            elevation = np.arctan2(direction[2], np.sqrt(direction[0] ** 2 + direction[1] ** 2))
            azimuth = np.arctan2(direction[1], direction[0])
            if low_el < elevation < high_el and low_az < azimuth < high_az:
                break
    else:
        elevation = np.deg2rad(elevation_min + (elevation_max - elevation_min) * np.random.rand())
        azimuth = np.deg2rad(azimuth_min + (azimuth_max - azimuth_min) * np.random.rand())
        polar = np.pi / 2 - elevation
        direction = np.array([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)])
        radius = np.random.uniform(radius_min, radius_max)
    return direction * radius + np.array(center)


def _clockwise_of(edge: np.ndarray, point: np.ndarray) -> bool:
    """Whether ``point`` (x, y) lies strictly clockwise of the ray along ``edge`` (x, y)."""
    return bool(edge[1] * point[0] - edge[0] * point[1] > 0)


def disk(center: Any, radius: float, rotation: Optional[Any] = None, sample_from: str = "disk",
         start_angle: float = 0, end_angle: float = 180) -> np.ndarray:
    """A point of a disk of ``radius`` metres around ``center``: of its area (``"disk"``), its circle
    (``"circle"``), or the sector / arc between ``start_angle`` and ``end_angle`` degrees (counter-clockwise
    from +X, at most 180 apart). The disk lies in the XY plane turned by ``rotation`` (Euler XYZ, radians).

    Draws, as BlenderProc: for ``disk``/``sector`` first one uniform ``u`` (radius ``radius * sqrt(u)``),
    then two normal numbers for the direction, again until a sector/arc point falls between the angles.
    """
    if sample_from not in ("disk", "circle", "sector", "arc"):
        raise ValueError(f"bproc.sampler.disk: unknown sample_from {sample_from!r} (disk, circle, sector or arc)")
    partial = sample_from in ("arc", "sector")
    if partial and not (start_angle < end_angle and abs(start_angle - end_angle) <= 180):
        raise ValueError(f"bproc.sampler.disk: start_angle ({start_angle}) must be smaller than end_angle "
                         f"({end_angle}) and at most 180 degrees from it")
    magnitude = radius if sample_from in ("circle", "arc") else radius * np.sqrt(np.random.uniform())
    point = _scaled(_normal_draws(2), magnitude)
    if partial:
        start = np.array([np.cos(np.deg2rad(start_angle)), np.sin(np.deg2rad(start_angle))])
        end = np.array([np.cos(np.deg2rad(end_angle)), np.sin(np.deg2rad(end_angle))])
        while _clockwise_of(start, point) or not _clockwise_of(end, point):
            point = _scaled(_normal_draws(2), magnitude)
    turn = build_transformation_mat([0.0, 0.0, 0.0], [0.0, 0.0, 0.0] if rotation is None else rotation)
    return turn[:3, :3] @ np.append(point, 0.0) + np.array(center)
