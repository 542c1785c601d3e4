"""angle_weighted_normals is trimesh's Trimesh.vertex_normals bit for bit (trimesh is the oracle) on loaded
assets, a random triangle soup with shared vertices, degenerate faces and unreferenced vertices, and a sphere;
and its normals point along the analytic normal of a sphere."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from hybridgen.scene.vertex_normals import angle_weighted_normals

ASSETS = Path(__file__).resolve().parents[2] / "configs" / "assets"


def _soup() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(11)
    vertices = rng.normal(size=(60, 3)) * [1.0, 2.0, 0.3]
    faces = rng.integers(0, 50, size=(150, 3))  # vertices 50..59 unreferenced
    faces[:5, 1] = faces[:5, 0]  # two corners on one vertex
    vertices[40] = vertices[41]  # a zero-length edge where faces use both
    faces[5:8] = [[40, 41, 3], [41, 40, 7], [3, 40, 41]]
    faces[8] = [1, 2, 1]
    return vertices, faces


def _meshes() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    loaded = {name: trimesh.load(ASSETS / name, force="mesh", process=False) for name in ("crate.obj", "knot.obj")}
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.8)
    return {**{name: (np.asarray(m.vertices), np.asarray(m.faces)) for name, m in loaded.items()}, "soup": _soup(),
            "sphere": (np.asarray(sphere.vertices), np.asarray(sphere.faces)),
            "float32 sphere": (np.asarray(sphere.vertices, np.float32), np.asarray(sphere.faces, np.int32)),
            "no faces": (np.ones((3, 3)), np.zeros((0, 3), dtype=np.int64))}


@pytest.mark.parametrize("name", sorted(_meshes()))
def test_equals_trimesh_vertex_normals(name: str) -> None:
    vertices, faces = _meshes()[name]
    expected = np.asarray(trimesh.Trimesh(vertices, faces, process=False).vertex_normals)
    assert np.array_equal(angle_weighted_normals(vertices, faces), expected)


def test_sphere_normals_are_radial() -> None:
    vertices, faces = _meshes()["sphere"]
    normals = angle_weighted_normals(vertices, faces)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)
    assert np.min(np.sum(normals * vertices / 0.8, axis=1)) > np.cos(np.radians(1.0))
