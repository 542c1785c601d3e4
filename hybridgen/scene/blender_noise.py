"""The noise bases of Blender's procedural (legacy) textures, their turbulence sum and hard/soft forms, as NumPy
array code: what ``noise_basis`` / ``noise_type`` / ``noise_depth`` mean on a ``bpy.types.Texture``.

Coordinates are texture space (a texture divides the point by its ``noise_scale`` first, so features are about
``noise_scale`` apart); values of one basis are unsigned, about [0, 1] (Voronoi distances can pass 1).

- ``BLENDER_ORIGINAL``, ``ORIGINAL_PERLIN``, ``IMPROVED_PERLIN``: gradient noise - hybridgen's Perlin noise
  (:func:`hybridgen.scene.gradient_noise.perlin`, cells of 1) as ``0.5 + k x perlin`` clipped to [0, 1], ``k``
  giving each basis the spread Blender 4.2's has (measured with bpy, ``tools/blender_textures.py``: standard
  deviation 0.182, 0.140, 0.133 over random points; correlation 0.44 at half a cell, ~0 at one cell). Each
  basis reads the lattice at its own offset, so they are independent. Blender's own gradient functions are not
  reproduced value for value: the statistics are.
- ``VORONOI_F1`` .. ``VORONOI_F4``: distance to the 1st .. 4th nearest feature point, one point per unit cell
  (placed by a hash of the cell); ``VORONOI_F2_F1`` = F2 - F1; ``VORONOI_CRACKLE`` = min(1, 10 (F2 - F1)).
- ``CELL_NOISE``: one hashed value in [0, 1) per unit cell.

:func:`turbulence` is Blender's sum of ``depth + 1`` octaves (each twice the frequency, half the amplitude)
divided so its largest possible value is that of one octave; ``hard`` folds each octave as |2 n - 1|.
"""
from __future__ import annotations

import numpy as np

from .gradient_noise import NUMPY, hash_uint3, perlin

GRADIENT_SPREAD = {"BLENDER_ORIGINAL": 0.676, "ORIGINAL_PERLIN": 0.520, "IMPROVED_PERLIN": 0.492}
"""``k`` of each gradient basis: Blender's measured standard deviation over that of hybridgen's Perlin noise
(0.2697)."""
VORONOI_RANK = {"VORONOI_F1": 0, "VORONOI_F2": 1, "VORONOI_F3": 2, "VORONOI_F4": 3}
NOISE_BASES = tuple(GRADIENT_SPREAD) + tuple(VORONOI_RANK) + ("VORONOI_F2_F1", "VORONOI_CRACKLE", "CELL_NOISE")
"""Blender's ``noise_basis`` names."""
_LATTICE_SHIFT = {name: 37.0 * index for index, name in enumerate(NOISE_BASES)}
"""Each basis reads the noise lattice this many cells away (independent bases)."""
DISTANCE_METRICS = ("DISTANCE", "DISTANCE_SQUARED", "MANHATTAN", "CHEBYCHEV", "MINKOVSKY_HALF", "MINKOVSKY_FOUR",
                    "MINKOVSKY")
_NEIGHBOURS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)], dtype=np.float64)


def _points(p: np.ndarray) -> np.ndarray:
    return np.asarray(p, dtype=np.float64).reshape(-1, 3)


def cell_hash(cells: np.ndarray, channel: int = 0) -> np.ndarray:
    """A value in [0, 1) per integer cell (N, 3) - independent per ``channel``."""
    lattice = NUMPY.lattice(cells.astype(np.float32))
    with np.errstate(over="ignore"):
        hashed = hash_uint3(lattice[:, 0], lattice[:, 1] + np.uint32(7919 * channel), lattice[:, 2])
    return hashed.astype(np.float64) / 4294967296.0


def feature_distances(p: np.ndarray, metric: str = "DISTANCE", exponent: float = 2.5) -> tuple[np.ndarray, np.ndarray]:
    """Distances (N, 4) from each point to its 4 nearest feature points (one per unit cell, hashed), in the
    ``metric`` (Blender's ``distance_metric``; ``exponent`` for ``MINKOVSKY``), and the cells (N, 4, 3) of
    those points."""
    p = _points(p)
    base = np.floor(p)
    cells = base[:, None, :] + _NEIGHBOURS[None]  # (N, 27, 3)
    flat = cells.reshape(-1, 3)
    jitter = np.stack([cell_hash(flat, channel) for channel in range(3)], axis=1).reshape(cells.shape)
    d = np.abs(cells + jitter - p[:, None, :])
    if metric == "DISTANCE":
        dist = np.sqrt((d * d).sum(axis=2))
    elif metric == "DISTANCE_SQUARED":
        dist = (d * d).sum(axis=2)
    elif metric == "MANHATTAN":
        dist = d.sum(axis=2)
    elif metric == "CHEBYCHEV":
        dist = d.max(axis=2)
    else:
        power = {"MINKOVSKY_HALF": 0.5, "MINKOVSKY_FOUR": 4.0}.get(metric, exponent)
        dist = (d ** power).sum(axis=2) ** (1.0 / power)
    order = np.argsort(dist, axis=1)[:, :4]
    return np.take_along_axis(dist, order, axis=1), np.take_along_axis(cells, order[:, :, None], axis=1)


def basis(name: str, p: np.ndarray) -> np.ndarray:
    """The unsigned basis ``name`` (module doc) at the points ``p`` (N, 3), texture space."""
    p = _points(p) + _LATTICE_SHIFT[name]
    if name in GRADIENT_SPREAD:
        q = p.astype(np.float32)
        gradient = perlin(NUMPY, q[:, 0], q[:, 1], q[:, 2]).astype(np.float64)
        return np.clip(0.5 + GRADIENT_SPREAD[name] * gradient, 0.0, 1.0)
    if name == "CELL_NOISE":
        return cell_hash(np.floor(p))
    distances = feature_distances(p)[0]
    if name in VORONOI_RANK:
        return distances[:, VORONOI_RANK[name]]
    if name == "VORONOI_F2_F1":
        return distances[:, 1] - distances[:, 0]
    return np.minimum(1.0, 10.0 * (distances[:, 1] - distances[:, 0]))  # VORONOI_CRACKLE


def signed_basis(name: str, p: np.ndarray) -> np.ndarray:
    """``2 basis - 1``: about [-1, 1], mean about 0 for the gradient bases."""
    return 2.0 * basis(name, p) - 1.0


def noise(name: str, p: np.ndarray, hard: bool = False) -> np.ndarray:
    """One octave: the basis, or |2 n - 1| when ``hard`` (Blender's ``noise_type`` HARD_NOISE)."""
    value = basis(name, p)
    return np.abs(2.0 * value - 1.0) if hard else value


def turbulence(name: str, p: np.ndarray, depth: int, hard: bool = False) -> np.ndarray:
    """``depth + 1`` octaves of :func:`noise` summed (octave i at 2^i times the frequency, 2^-i the amplitude),
    times 2^depth / (2^(depth+1) - 1) so the octaves' amplitudes sum to 1."""
    p = _points(p)
    depth = max(int(depth), 0)
    total = np.zeros(len(p))
    for octave in range(depth + 1):
        total += noise(name, p * 2.0 ** octave, hard) * 0.5 ** octave
    return total * (2.0 ** depth / (2.0 ** (depth + 1) - 1.0))
