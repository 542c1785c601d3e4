"""Light sampling of a constant-color world seen through openings (a sky through a window). Off by default.

A constant-color world next to other emitters gets no light samples (:mod:`hybridgen.render.pathtrace.light_selection`):
BSDF sampling alone finds it, which is the better technique where the world fills much of the sky above a
surface. Indoors it is not: in the window room of tools/color_quality.py the sky, seen through the window and
the slits at the side walls' ends, is 87 % of the light and 94 % of the variance (64 spp, the sun and the sky
turned off in turn), and a diffuse point of the room finds an opening with a cosine-distributed direction a
few times in a hundred.

With :data:`ENABLED`, per keypoint, before the first samples, :func:`learn` looks from the surfaces the camera
sees (a grid of camera rays, and one cosine bounce from each hit) in cosine-distributed directions and
counts, per voxel of a :data:`VOXELS` grid over those points and per cell of an equal-area grid of directions
(``Z_CELLS`` bands of z, ``PHI_CELLS`` sectors of azimuth), the rays that reach the world unoccluded. If fewer
than :data:`MAX_OPEN_FRACTION` of them do (the scene is enclosed), the integrator
(:mod:`hybridgen.render.pathtrace.clamped_path`) adds one light sample of the world per vertex, its direction drawn from
its voxel's counts mixed with the uniform sphere (:data:`UNIFORM_SHARE`, so every direction keeps a positive
density), MIS-weighted (power heuristic) against BSDF sampling, which keeps finding the world too. Any positive
density gives the same expectation, so the estimate stays unbiased (tests/render/test_world_guide.py); the
learning pass uses a fixed pattern that depends on the pose only, so the result stays a pure function of the
seed. Open scenes (the world visible over most of the hemisphere: the tabletops) are left as they were.

Why it is off (session 7, docs/color_quality.md; window room, 320x240, Owen-Sobol samples, loaded 2-core
machine): at 128 spp fixed it halves the variance between two seeds (8-bit sRGB: 17.8 -> 7.9) for +60 % CPU
(2.9-3.1 -> 5.0 s, learning included), 30 % less variance x CPU; but in the default pipeline (adaptive, 1024-spp
cap, OIDN) it buys +0.3 dB (50.60 -> 50.90 dB against a 4096-spp reference) for +36 % sampling CPU (20.9 -> 28.5 s):
the cap binds in most pixels and the denoiser evens out the rest, and the window room already meets the goal
without it (49.1 dB vs Cycles' 48.9 at 0.44 of its CPU). Session 6's grid (4 x 4 x 4 voxels, 16 x 32 cells, 32
learning rays per point) cost the same and kept more variance (9.7); the cell search and the MIS density per
vertex are a third of the extra cost (no vertex guided: +0.56 s), the shadow ray and BSDF evaluation the rest;
guiding only the first one or two vertices of a path kept most of the cost and little of the gain (variance 16.4 /
13.4 at 3.96 / 4.33 s).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

Z_CELLS, PHI_CELLS = 8, 16
"""Equal-area direction grid: bands of equal height in z (world up), sectors of equal azimuth."""
UNIFORM_SHARE = 0.2
"""Share of the world's light samples drawn uniformly over the sphere (the rest from the learned counts)."""
ENABLED = False
"""Whether :meth:`hybridgen.render.pathtrace.adaptive_sampling.PixelTracer.guide_world` learns a guide (see the module
docstring for why it is off)."""
MAX_OPEN_FRACTION = 0.25
"""The world is light-sampled only if fewer than this share of the learning rays reach it."""
GRID = (64, 48)
"""Camera rays of the learning pass (film positions, cell centres)."""
DIRECTIONS = 128
"""Cosine-distributed rays per surface point of the learning pass."""


VOXELS = (8, 8, 8)
"""Cells of the box around the learning points (x, y, z), each with its own direction counts."""
MIN_VOXEL_COUNT = 64
"""A voxel with fewer world-reaching learning rays uses the counts of all voxels together."""


@dataclass(frozen=True)
class WorldGuide:
    """The learned direction distributions: per voxel and direction cell the probability ``pmf`` and its
    running sum within the voxel ``cdf`` (float32, voxel-major, cell ``iz * PHI_CELLS + iphi``), the voxel box
    (``low``, ``high``, m) and the share of learning rays that reached the world."""

    pmf: np.ndarray
    cdf: np.ndarray
    low: np.ndarray
    high: np.ndarray
    open_fraction: float


def cell_of(d: np.ndarray) -> np.ndarray:
    """Direction cell index of unit directions ``d`` (N x 3, world frame)."""
    iz = np.clip(((d[:, 2] + 1.0) * 0.5 * Z_CELLS).astype(np.int64), 0, Z_CELLS - 1)
    phi = np.arctan2(d[:, 1], d[:, 0]) % (2 * math.pi)
    iphi = np.clip((phi / (2 * math.pi) * PHI_CELLS).astype(np.int64), 0, PHI_CELLS - 1)
    return iz * PHI_CELLS + iphi


def voxel_of(p: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Voxel index of points ``p`` (N x 3, clamped into the box)."""
    n = np.array(VOXELS)
    ijk = np.clip(((p - low) / np.maximum(high - low, 1e-6) * n).astype(np.int64), 0, n - 1)
    return (ijk[:, 0] * n[1] + ijk[:, 1]) * n[2] + ijk[:, 2]


def from_rays(points: np.ndarray, directions: np.ndarray, free: np.ndarray) -> WorldGuide | None:
    """The guide of learning rays from ``points`` in ``directions`` (unit, N x 3) of which ``free`` reached
    the world; None when none did."""
    if not free.any():
        return None
    low, high = points.min(axis=0), points.max(axis=0)
    cells, voxels = Z_CELLS * PHI_CELLS, int(np.prod(VOXELS))
    counts = np.zeros((voxels, cells))
    np.add.at(counts, (voxel_of(points[free], low, high), cell_of(directions[free])), 1.0)
    total = counts.sum(axis=0)
    sparse = counts.sum(axis=1) < MIN_VOXEL_COUNT
    counts[sparse] = total
    pmf = (counts / counts.sum(axis=1, keepdims=True)).astype(np.float32)
    cdf = np.cumsum(pmf.astype(np.float64), axis=1)
    cdf /= cdf[:, -1:]
    return WorldGuide(pmf.ravel(), cdf.astype(np.float32).ravel(), low, high, float(free.mean()))


def _cosine_directions(n: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Cosine-distributed unit directions about unit normals ``n`` (N x 3) from uniform ``u`` (N x 2)."""
    r, phi = np.sqrt(u[:, 0]), 2 * math.pi * u[:, 1]
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1 - u[:, 0]))], axis=1)
    helper = np.where(np.abs(n[:, :1]) > 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    t = np.cross(helper, n)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t)
    return local[:, :1] * t + local[:, 1:2] * b + local[:, 2:] * n


def learn(mi_scene: Any, sensor: Any) -> WorldGuide | None:
    """Cosine rays from the surfaces ``sensor`` sees (and one bounce further) and whether they reach the world,
    as described in the module docstring; deterministic (a fixed pattern)."""
    import mitsuba as mi

    rng = np.random.default_rng(0x5EED)
    w, h = GRID
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(u.ravel(), v.ravel()), mi.Point2f(0.5, 0.5))
    origin = np.stack([np.asarray(c, np.float64) for c in ray.o], axis=1)
    direction = np.stack([np.asarray(c, np.float64) for c in ray.d], axis=1)
    points, directions, free = [], [], []
    for _ in range(2):
        si = mi_scene.ray_intersect(mi.Ray3f(mi.Point3f(*origin.T.astype(np.float32)),
                                             mi.Vector3f(*direction.T.astype(np.float32))))
        hit = np.asarray(si.is_valid(), bool)
        if not hit.any():
            break
        p = np.stack([np.asarray(c, np.float64) for c in si.p], axis=1)[hit]
        n = np.stack([np.asarray(c, np.float64) for c in si.sh_frame.n], axis=1)[hit]
        n *= np.where((n * direction[hit]).sum(axis=1, keepdims=True) > 0, -1.0, 1.0)  # towards the viewer
        p, n = np.repeat(p, DIRECTIONS, axis=0), np.repeat(n, DIRECTIONS, axis=0)
        d = _cosine_directions(n, rng.random((len(p), 2)))
        spawned = mi.Ray3f(mi.Point3f(*(p + n * 1e-4).T.astype(np.float32)), mi.Vector3f(*d.T.astype(np.float32)))
        points.append(p)
        directions.append(d)
        free.append(~np.asarray(mi_scene.ray_test(spawned), bool))
        keep = rng.random(len(d)) < 1.0 / DIRECTIONS  # one continuing ray per point on average
        origin, direction = p[keep] + n[keep] * 1e-4, d[keep]
    if not points:
        return None
    return from_rays(np.concatenate(points), np.concatenate(directions), np.concatenate(free))


def density(guide: WorldGuide, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Solid-angle density (sr^-1) of the mixture the integrator samples at points ``p`` in unit directions
    ``d`` (N x 3 each; NumPy twin of :func:`pdf`, for tests)."""
    cells = Z_CELLS * PHI_CELLS
    mass = guide.pmf[voxel_of(p, guide.low, guide.high) * cells + cell_of(d)]
    return UNIFORM_SHARE / (4 * math.pi) + (1 - UNIFORM_SHARE) * mass * cells / (4 * math.pi)


# ------------------------------------------------------------------------------------------ Dr.Jit side
@dataclass
class JitGuide:
    """A :class:`WorldGuide` as Dr.Jit arrays for the integrator (opaque, so one kernel serves every
    keypoint), with the world's radiance."""

    pmf: Any
    cdf: Any
    low: Any
    scale: Any
    radiance: Any

    @staticmethod
    def of(guide: WorldGuide, radiance: list[float]) -> "JitGuide":
        import drjit as dr
        import mitsuba as mi

        scale = np.array(VOXELS) / np.maximum(guide.high - guide.low, 1e-6)
        return JitGuide(mi.Float(guide.pmf), mi.Float(guide.cdf), dr.opaque(mi.Vector3f, guide.low.tolist()),
                        dr.opaque(mi.Vector3f, scale.tolist()), dr.opaque(mi.Color3f, radiance))


def _voxel(guide: JitGuide, p: Any) -> Any:
    import drjit as dr
    import mitsuba as mi

    nx, ny, nz = VOXELS
    q = (p - guide.low) * guide.scale
    i = mi.UInt32(dr.clip(dr.floor(q.x), 0, nx - 1))
    j = mi.UInt32(dr.clip(dr.floor(q.y), 0, ny - 1))
    k = mi.UInt32(dr.clip(dr.floor(q.z), 0, nz - 1))
    return (i * ny + j) * nz + k


def _cell(d: Any) -> Any:
    import drjit as dr
    import mitsuba as mi

    iz = mi.UInt32(dr.clip(dr.floor((d.z + 1.0) * 0.5 * Z_CELLS), 0, Z_CELLS - 1))
    phi = dr.atan2(d.y, d.x)
    phi = dr.select(phi < 0, phi + 2 * math.pi, phi)
    iphi = mi.UInt32(dr.clip(dr.floor(phi * (PHI_CELLS / (2 * math.pi))), 0, PHI_CELLS - 1))
    return iz * PHI_CELLS + iphi


def pdf(guide: JitGuide, p: Any, d: Any, active: Any = True) -> Any:
    """Solid-angle density of the mixture at points ``p`` in world directions ``d`` (Dr.Jit)."""
    import drjit as dr
    import mitsuba as mi

    cells = Z_CELLS * PHI_CELLS
    mass = dr.gather(mi.Float, guide.pmf, _voxel(guide, p) * cells + _cell(d), active)
    return UNIFORM_SHARE / (4 * math.pi) + (1 - UNIFORM_SHARE) * mass * (cells / (4 * math.pi))


def sample(guide: JitGuide, p: Any, choice: Any, sample2: Any, active: Any = True) -> tuple[Any, Any]:
    """A world direction from the mixture at points ``p`` and its density (Dr.Jit): uniform over the sphere
    where ``choice`` < :data:`UNIFORM_SHARE`, else a cell of ``p``'s voxel by its ``cdf`` (``sample2.x``,
    its remainder placing z in the band) and the azimuth in the sector by ``sample2.y``."""
    import drjit as dr
    import mitsuba as mi

    cells = Z_CELLS * PHI_CELLS
    base = _voxel(guide, p) * cells
    x = sample2.x
    local = dr.binary_search(0, cells - 1, lambda i: dr.gather(mi.Float, guide.cdf, base + i, active) <= x)
    index = base + mi.UInt32(dr.minimum(local, cells - 1))
    upper = dr.gather(mi.Float, guide.cdf, index, active)
    mass = dr.gather(mi.Float, guide.pmf, index, active)
    within = dr.clip((x - (upper - mass)) / dr.maximum(mass, 1e-12), 0.0, 0.99999994)
    cell = index - base
    iz, iphi = cell // PHI_CELLS, cell % PHI_CELLS
    z = (mi.Float(iz) + within) * (2.0 / Z_CELLS) - 1.0
    phi = (mi.Float(iphi) + sample2.y) * (2 * math.pi / PHI_CELLS)
    r = dr.safe_sqrt(1.0 - z * z)
    guided = mi.Vector3f(r * dr.cos(phi), r * dr.sin(phi), z)
    d = dr.select(choice < UNIFORM_SHARE, mi.warp.square_to_uniform_sphere(sample2), guided)
    return d, pdf(guide, p, d, active)


def constant_world_radiance(mi_scene: Any) -> Any:
    """The radiance (mi.Color3f) of ``mi_scene``'s world if it is a constant-color emitter that gets no light
    samples (weight 0, :mod:`hybridgen.render.pathtrace.light_selection`), else None."""
    import mitsuba as mi

    env = mi_scene.environment()
    if env is None or "Constant" not in env.class_name():
        return None
    params = mi.traverse(env)
    if "sampling_weight" in params and float(params["sampling_weight"]) > 0:
        return None
    if "sampling_weight" not in params and len(mi_scene.emitters()) <= 1:
        return None
    si = mi.SurfaceInteraction3f()
    value = np.asarray(env.eval(si), np.float64).reshape(-1)[:3]
    return None if not np.any(value > 0) else [float(c) for c in value]
