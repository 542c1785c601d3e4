"""Built-in samplers (BlenderProc's names and parameters). Angles in degrees where BlenderProc uses degrees
(ShellSampler, DiskSampler), radians for rotations (UniformSO3 returns Blender XYZ Euler angles); metres."""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ..input_paths import describe_glob_miss, glob_inputs
from .sampler_table import DrawContext, register_sampler


def _vec(value: Any, n: int, name: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64).ravel()
    if array.size != n or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be {n} finite numbers, got {value!r}")
    return array


def _ordered(low: Any, high: Any, what: str) -> None:
    if np.any(np.asarray(low, float) > np.asarray(high, float)):
        raise ValueError(f"{what}: min {low} > max {high}")


def _check_box(p: dict[str, Any]) -> None:
    if "min" in p and "max" in p:
        _ordered(_vec(p["min"], 3, "min"), _vec(p["max"], 3, "max"), "Uniform3d")


@register_sampler("sampler.Uniform3d", "Uniform3dSampler", validate=_check_box)
def uniform3d(ctx: DrawContext, min: Sequence[float], max: Sequence[float]) -> np.ndarray:
    """A point uniform in the box [min, max] (m)."""
    low, high = _vec(min, 3, "min"), _vec(max, 3, "max")
    _ordered(low, high, "Uniform3d")
    return ctx.rng.uniform(low, high)


def _check_radius(p: dict[str, Any]) -> None:
    if "radius" in p and not p["radius"] > 0:
        raise ValueError(f"radius must be > 0, got {p['radius']}")
    if "mode" in p and str(p["mode"]).upper() not in ("SURFACE", "INTERIOR"):
        raise ValueError(f"mode must be SURFACE or INTERIOR, got {p['mode']!r}")


def _unit_vector(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _ball_point(rng: np.random.Generator, radius: float, mode: str) -> np.ndarray:
    scale = radius if mode.upper() == "SURFACE" else radius * rng.uniform() ** (1 / 3)
    return _unit_vector(rng) * scale


@register_sampler("sampler.Sphere", "SphereSampler", validate=_check_radius)
def sphere(ctx: DrawContext, center: Sequence[float], radius: float, mode: str = "SURFACE") -> np.ndarray:
    """A point on (SURFACE) or in (INTERIOR) the sphere, uniform by area / volume."""
    _check_radius({"radius": radius, "mode": mode})
    return _vec(center, 3, "center") + _ball_point(ctx.rng, float(radius), mode)


def _check_shell(p: dict[str, Any]) -> None:
    for low, high in (("radius_min", "radius_max"), ("elevation_min", "elevation_max"),
                      ("azimuth_min", "azimuth_max")):
        if low in p and high in p:
            _ordered(p[low], p[high], "ShellSampler")
    if "radius_min" in p and p["radius_min"] < 0:
        raise ValueError("radius_min must be >= 0")
    for key in ("elevation_min", "elevation_max"):
        if key in p and not -90 <= p[key] <= 90:
            raise ValueError(f"{key} must be in -90..90 degrees, got {p[key]}")


@register_sampler("sampler.Shell", "ShellSampler", validate=_check_shell)
def shell(ctx: DrawContext, center: Sequence[float], radius_min: float, radius_max: float,
          elevation_min: float = -90.0, elevation_max: float = 90.0, azimuth_min: float = -180.0,
          azimuth_max: float = 180.0, uniform_volume: bool = False, uniform_elevation: bool = False) -> np.ndarray:
    """A point between two spheres, within elevation/azimuth ranges (degrees; elevation from the XY plane).

    Directions are uniform on the sphere's band (or, with ``uniform_elevation`` as in BlenderProc, the
    elevation angle is uniform in degrees); the radius is uniform (or uniform by volume)."""
    _check_shell(dict(radius_min=radius_min, radius_max=radius_max, elevation_min=elevation_min,
                      elevation_max=elevation_max, azimuth_min=azimuth_min, azimuth_max=azimuth_max))
    rng = ctx.rng
    if uniform_elevation:
        z = math.sin(math.radians(rng.uniform(elevation_min, elevation_max)))
    else:
        z = rng.uniform(math.sin(math.radians(elevation_min)), math.sin(math.radians(elevation_max)))
    azimuth = math.radians(rng.uniform(azimuth_min, azimuth_max))
    horizontal = math.sqrt(max(0.0, 1 - z * z))
    direction = np.array([horizontal * math.cos(azimuth), horizontal * math.sin(azimuth), z])
    if uniform_volume:
        radius = (rng.uniform(radius_min ** 3, radius_max ** 3)) ** (1 / 3)
    else:
        radius = rng.uniform(radius_min, radius_max)
    return _vec(center, 3, "center") + direction * radius


@register_sampler("sampler.PartSphere", "PartSphereSampler", validate=_check_radius)
def part_sphere(ctx: DrawContext, center: Sequence[float], radius: float, mode: str = "SURFACE",
                part_sphere_dir_vector: Sequence[float] = (0.0, 0.0, 1.0),
                distance_above_center: float = 0.0) -> np.ndarray:
    """A sphere point whose offset along ``part_sphere_dir_vector`` exceeds ``distance_above_center`` (m)."""
    _check_radius({"radius": radius, "mode": mode})
    if distance_above_center >= radius:
        raise ValueError(f"distance_above_center ({distance_above_center}) must be < radius ({radius})")
    direction = _vec(part_sphere_dir_vector, 3, "part_sphere_dir_vector")
    direction /= np.linalg.norm(direction)
    for _ in range(10000):
        offset = _ball_point(ctx.rng, float(radius), mode)
        if offset @ direction > distance_above_center:
            return _vec(center, 3, "center") + offset
    raise ValueError("PartSphereSampler found no point above the cut in 10000 tries")


def _check_disk(p: dict[str, Any]) -> None:
    if "radius" in p and not p["radius"] > 0:
        raise ValueError(f"radius must be > 0, got {p['radius']}")
    if "sample_from" in p and p["sample_from"] not in ("disk", "circle", "arc", "sector"):
        raise ValueError(f"sample_from must be disk, circle, arc or sector, got {p['sample_from']!r}")
    if "start_angle" in p and "end_angle" in p:
        _ordered(p["start_angle"], p["end_angle"], "DiskSampler angles")


@register_sampler("sampler.Disk", "DiskSampler", validate=_check_disk)
def disk(ctx: DrawContext, center: Sequence[float], radius: float, rotation: Sequence[float] = (0.0, 0.0, 0.0),
         sample_from: str = "disk", start_angle: float = 0.0, end_angle: float = 180.0) -> np.ndarray:
    """A point of a disk (uniform by area), its circle, an arc or a sector (angles in degrees, in the disk's
    local XY plane rotated by Euler XYZ ``rotation`` radians)."""
    from ..scene.frames import euler_xyz_to_matrix

    _check_disk(dict(radius=radius, sample_from=sample_from, start_angle=start_angle, end_angle=end_angle))
    rng = ctx.rng
    if sample_from in ("disk", "circle"):
        angle = rng.uniform(0, 2 * math.pi)
    else:
        angle = math.radians(rng.uniform(start_angle, end_angle))
    r = radius if sample_from in ("circle", "arc") else radius * math.sqrt(rng.uniform())
    local = np.array([r * math.cos(angle), r * math.sin(angle), 0.0])
    return _vec(center, 3, "center") + euler_xyz_to_matrix(_vec(rotation, 3, "rotation")) @ local


@register_sampler("sampler.UniformSO3", "UniformSO3")
def uniform_so3(ctx: DrawContext, around_x: bool = True, around_y: bool = True, around_z: bool = True) -> np.ndarray:
    """Blender XYZ Euler angles (rad) of a rotation uniform over SO(3), or uniform angles about the
    enabled axes only."""
    from scipy.spatial.transform import Rotation

    if around_x and around_y and around_z:
        return Rotation.random(random_state=ctx.rng).as_euler("xyz")
    angles = ctx.rng.uniform(0, 2 * math.pi, size=3)
    return angles * np.array([around_x, around_y, around_z], dtype=float)


def _check_value(p: dict[str, Any]) -> None:
    if p.get("type", "float") not in ("float", "int", "bool"):
        raise ValueError(f"type must be float, int or bool, got {p['type']!r}")
    if p.get("mode", "uniform") not in ("uniform", "normal"):
        raise ValueError(f"mode must be uniform or normal, got {p['mode']!r}")
    if "min" in p and "max" in p:
        _ordered(p["min"], p["max"], "Value")
    if "std_dev" in p and p["std_dev"] < 0:
        raise ValueError("std_dev must be >= 0")


@register_sampler("sampler.Value", "ValueSampler", validate=_check_value)
def value(ctx: DrawContext, type: str = "float", mode: str = "uniform", min: float = 0.0, max: float = 1.0,
          mean: float = 0.0, std_dev: float = 1.0) -> Any:
    """A number: uniform in [min, max] (ints inclusive) or normal(mean, std_dev); bool: a fair coin."""
    _check_value(dict(type=type, mode=mode, min=min, max=max, std_dev=std_dev))
    rng = ctx.rng
    if type == "bool":
        return bool(rng.uniform() < 0.5)
    if type == "int":
        return int(rng.integers(int(min), int(max) + 1)) if mode == "uniform" else int(round(rng.normal(mean, std_dev)))
    return float(rng.uniform(min, max)) if mode == "uniform" else float(rng.normal(mean, std_dev))


def _check_color(p: dict[str, Any]) -> None:
    if "min" in p and "max" in p:
        low, high = np.asarray(p["min"], float), np.asarray(p["max"], float)
        if low.shape != high.shape or low.size not in (3, 4):
            raise ValueError("min and max must both be RGB or RGBA")
        _ordered(low, high, "Color")


@register_sampler("sampler.Color", "ColorSampler", validate=_check_color)
def color(ctx: DrawContext, min: Sequence[float] = (0, 0, 0, 1), max: Sequence[float] = (1, 1, 1, 1),
          grey: bool = False) -> np.ndarray:
    """An RGB(A) color uniform per channel in [min, max]; ``grey`` (BlenderProc's): one draw, from the first
    channel's range, for R, G and B."""
    _check_color({"min": min, "max": max})
    drawn = ctx.rng.uniform(np.asarray(min, float), np.asarray(max, float))
    if grey:
        drawn[:3] = drawn[0]
    return drawn


@register_sampler("sampler.Path", "PathSampler")
def path(ctx: DrawContext, path: str) -> str:
    """A random file among those matching the glob ``path`` (sorted, so the draw is reproducible), relative
    to the working directory or, when nothing matches there, to the config's folder."""
    matches = glob_inputs(path)  # from the working directory, else the config's folder
    if not matches:
        raise ValueError(describe_glob_miss(path))
    return matches[int(ctx.rng.integers(len(matches)))]
