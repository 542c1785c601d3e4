"""Catmull-Clark (hybridgen.scene.catmull_clark) on a regular grid - the Rock Essentials ground tile
(hybridgen.scene.ground_tile) - against analytic limits and against Blender 4.2's Subdivision Surface modifier
(defaults), whose positions are stored below: measured with bpy 4.2 on a 2 m plane subdivided with 2 cuts (4 x 4
vertices) whose heights are BLENDER_CONTROL_Z (a Displace modifier with a 4 x 4 image on UV coordinates,
strength 1), then Subdivision at level 2."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.scene import catmull_clark
from hybridgen.scene.ground_tile import GroundTile, grid_quads
from hybridgen.scene.polygon_mesh import PolygonMesh

# the displaced 4 x 4 control grid's heights (z, metres; rows along +y, columns along +x), as Blender displaced it
BLENDER_CONTROL_Z = [[-0.075, -0.14167, -0.13333, -0.075], [-0.2, 0.16667, -0.15, -0.2],
                     [-0.11667, -0.17222, 0.24444, -0.11667], [-0.075, -0.14167, -0.13333, -0.075]]
# Blender's level-2 heights, row-major in the order of the subdivided grid (each the nearest in x, y)
BLENDER_LEVEL2_Z = [
    [-0.10645, -0.10495, -0.11076, -0.12023, -0.12917, -0.13418, -0.13490, -0.13171, -0.12500, -0.11571, -0.10694, -0.10234, -0.10508],
    [-0.11918, -0.10280, -0.09035, -0.08409, -0.08454, -0.09125, -0.10153, -0.11208, -0.11962, -0.12190, -0.12096, -0.11950, -0.11860],
    [-0.13715, -0.10288, -0.07324, -0.05269, -0.04503, -0.05225, -0.06980, -0.09148, -0.11109, -0.12391, -0.13102, -0.13479, -0.13698],
    [-0.15460, -0.10575, -0.06258, -0.03073, -0.01579, -0.02111, -0.04133, -0.06891, -0.09629, -0.11752, -0.13301, -0.14473, -0.15458],
    [-0.16528, -0.11021, -0.06083, -0.02284, -0.00193, -0.00174, -0.01776, -0.04339, -0.07207, -0.09846, -0.12220, -0.14418, -0.16528],
    [-0.16463, -0.11481, -0.06911, -0.03166, -0.00659, 0.00317, -0.00068, -0.01521, -0.03753, -0.06503, -0.09619, -0.12980, -0.16463],
    [-0.15486, -0.11854, -0.08376, -0.05203, -0.02490, -0.00402, 0.00847, 0.01030, -0.00077, -0.02601, -0.06264, -0.10685, -0.15486],
    [-0.13989, -0.12051, -0.09990, -0.07681, -0.05002, -0.01970, 0.00826, 0.02656, 0.02789, 0.00718, -0.03173, -0.08277, -0.13989],
    [-0.12361, -0.11981, -0.11268, -0.09888, -0.07508, -0.04026, -0.00271, 0.02695, 0.03812, 0.02316, -0.01364, -0.06499, -0.12361],
    [-0.10946, -0.11600, -0.11845, -0.11271, -0.09465, -0.06263, -0.02511, 0.00693, 0.02250, 0.01360, -0.01593, -0.05924, -0.10944],
    [-0.09896, -0.11039, -0.11832, -0.11919, -0.10904, -0.08595, -0.05663, -0.02993, -0.01468, -0.01746, -0.03573, -0.06459, -0.09878],
    [-0.09314, -0.10455, -0.11456, -0.12081, -0.11997, -0.10991, -0.09424, -0.07801, -0.06624, -0.06288, -0.06747, -0.07824, -0.09256],
    [-0.09277, -0.09909, -0.10903, -0.12001, -0.12917, -0.13418, -0.13490, -0.13171, -0.12500, -0.11549, -0.10521, -0.09648, -0.09141]
]


def _plane(n: int, z: np.ndarray | None = None) -> np.ndarray:
    y, x = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n), indexing="ij")
    return np.stack([x, y, np.zeros_like(x) if z is None else z], axis=-1)


def _subdivided(grid: np.ndarray, levels: int) -> np.ndarray:
    """(V, 3) positions of the grid after ``levels`` Catmull-Clark levels."""
    n = grid.shape[0]
    quads = grid_quads(n, n)
    mesh = PolygonMesh(positions=grid.reshape(-1, 3), corners=quads.ravel(), starts=np.arange(0, quads.size + 1, 4),
                       part=np.zeros(len(quads), np.int64))
    out = catmull_clark.subdivide(mesh, levels).positions
    assert len(out) == ((n - 1) * 2 ** levels + 1) ** 2
    return out


def test_flat_stays_flat_and_the_mid_sides_stay_on_the_edge():
    out = _subdivided(_plane(5), 2)
    assert np.abs(out[:, 2]).max() == 0.0
    assert np.abs(out[:, :2]).max(axis=0) == pytest.approx([1.0, 1.0], abs=1e-12)


def test_linear_heights_are_reproduced():
    grid = _plane(9)
    grid[..., 2] = 0.3 * grid[..., 0] - 0.2 * grid[..., 1] + 0.1
    out = _subdivided(grid, 2)
    assert np.abs(out[:, 2] - (0.3 * out[:, 0] - 0.2 * out[:, 1] + 0.1)).max() < 1e-12


def test_bumpy_grid_against_blender_level_two():
    mesh = _plane(4, np.array(BLENDER_CONTROL_Z))
    quads = grid_quads(4, 4)
    poly = PolygonMesh(positions=mesh.reshape(-1, 3), corners=quads.ravel(), starts=np.arange(0, quads.size + 1, 4),
                       part=np.zeros(len(quads), np.int64))
    out = catmull_clark.subdivide(poly, 2).positions
    # Blender's level-2 vertices in the order of an unrounded 13 x 13 grid: match each by its x, y
    y, x = np.meshgrid(np.linspace(-1, 1, 13), np.linspace(-1, 1, 13), indexing="ij")
    nearest = np.argmin(np.linalg.norm(out[None, :, :2] - np.stack([x, y], -1).reshape(-1, 1, 2), axis=2), axis=1)
    heights = out[nearest, 2].reshape(13, 13)
    blender = np.array(BLENDER_LEVEL2_Z)
    assert np.abs(heights - blender).max() < 2e-5  # measured 7e-6 (bumps of +-0.25; the table's 5 decimals)


def test_corners_round_as_blender_rounds_them():
    out = _subdivided(_plane(4), 1)[:, :2]
    # Blender 4.2's level 1 has a vertex at (0.890625, -0.890625) (a corner) and at (0.65278, -0.98611) next to it
    assert np.linalg.norm(out - [0.890625, -0.890625], axis=1).min() < 1e-9  # the limit would be 0.888889
    assert np.linalg.norm(out - [0.65278, -0.98611], axis=1).min() < 1e-5
    assert np.abs(out).max() < 1.0 + 1e-12 and np.linalg.norm(out - [1.0, -1.0], axis=1).min() > 0.1  # rounded


def test_ground_tile_counts_and_levels_capped_at_three():
    vertices, faces, uvs = GroundTile(cuts=2, levels=5).mesh("tile")
    m = 3 * 8 + 1  # 4 x 4 control vertices, levels capped at 3
    assert len(vertices) == m * m and len(faces) == 2 * (m - 1) ** 2 and len(uvs) == m * m
