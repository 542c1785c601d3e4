"""BVHTree.find_nearest as mathutils': the nearest point of the tree's triangles to a point (inside a face, on an
edge, at a corner), the triangle's normal and index as ray_cast counts them, the distance, and nothing beyond the
distance limit; the closest-point code against a dense sampling of random triangles."""
from __future__ import annotations

import math

import numpy as np
import pytest

from hybridgen.bproc.types.bvh_tree import BVHTree
from hybridgen.scene.nearest_point import closest_points


def test_square() -> None:
    tree = BVHTree.FromPolygons([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (3, 0, 1), (4, 0, 1), (4, 1, 1)],
                                [(0, 1, 2, 3), (4, 5, 6)])
    location, normal, index, distance = tree.find_nearest((0.3, 0.8, 2.0))
    assert np.allclose(location, (0.3, 0.8, 0.0)) and np.allclose(normal, (0, 0, 1)) and distance == 2.0
    assert index == 1  # the quad's second triangle (0, 2, 3) holds x < y
    assert tree.ray_cast((0.3, 0.8, 2.0), (0, 0, -1))[2] == index
    location, _, index, distance = tree.find_nearest((2.0, 0.5, 0.0))  # between the quad's edge and the triangle
    assert np.allclose(location, (1.0, 0.5, 0.0)) and index in (0, 1) and distance == pytest.approx(1.0)
    location, _, index, distance = tree.find_nearest((5.0, 2.0, 1.0))  # beyond the triangle's corner (4, 1, 1)
    assert np.allclose(location, (4, 1, 1)) and index == 2 and distance == pytest.approx(math.sqrt(2))
    assert tree.find_nearest((0.5, 0.5, 3.0), distance=2.5) == (None, None, None, None)


def test_closest_points_against_sampling() -> None:
    rng = np.random.default_rng(4)
    a, b, c = (rng.normal(size=(40, 3)) for _ in range(3))
    grid = np.stack(np.meshgrid(np.linspace(0, 1, 121), np.linspace(0, 1, 121)), -1).reshape(-1, 2)
    grid = grid[grid.sum(1) <= 1]
    for _ in range(6):
        point = rng.normal(size=3) * 2
        ours = np.linalg.norm(closest_points(point, a, b, c) - point, axis=1)
        samples = a[:, None] + grid[None, :, :1] * (b - a)[:, None] + grid[None, :, 1:] * (c - a)[:, None]
        sampled = np.linalg.norm(samples - point, axis=2).min(axis=1)
        spacing = np.linalg.norm(np.stack([b - a, c - a, c - b], 1), axis=2).max(1) / 120
        assert np.all(ours <= sampled + 1e-12) and np.all(sampled - ours <= spacing)
