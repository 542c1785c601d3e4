"""Catmull-Clark on polygon meshes (hybridgen.scene.catmull_clark) against Blender 4.2's Subdivision Surface modifier
with its defaults, measured with bpy 4.2 by tools/blender_modifiers.py (the meshes are its MESHES: a 2 m cube, a
2 m plane, a 12-sided cylinder of radius 1 and height 2 with n-gon caps, the cube without its +x face), and the
polygons recovered from a loader's triangles (hybridgen.scene.polygon_recovery)."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from hybridgen.scene.catmull_clark import subdivide
from hybridgen.scene.mesh_object import MeshObject
from hybridgen.scene.polygon_mesh import PolygonMesh, from_parts

CUBE_V = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
CUBE_F = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
RING = [(np.cos(2 * np.pi * i / 12), np.sin(2 * np.pi * i / 12)) for i in range(12)]
CYLINDER_V = [(x, y, z) for z in (-1, 1) for x, y in RING]
CYLINDER_F = ([(i, (i + 1) % 12, 12 + (i + 1) % 12, 12 + i) for i in range(12)]
              + [tuple(range(11, -1, -1)), tuple(range(12, 24))])


def polygons(vertices: list, faces: list) -> PolygonMesh:
    return PolygonMesh(np.array(vertices, float), np.array([i for f in faces for i in f]),
                       np.cumsum([0] + [len(f) for f in faces]), np.zeros(len(faces), int))


def fan_triangles(faces: list) -> np.ndarray:
    """The faces as a loader triangulates them (a fan from the first corner), shuffled: no order to rely on."""
    triangles = [(f[0], f[i], f[i + 1]) for f in faces for i in range(1, len(f) - 1)]
    return np.array(triangles)[np.random.default_rng(4).permutation(len(triangles))]


@pytest.mark.parametrize("levels, counts", [(1, (26, 24)), (2, (98, 96)), (3, (386, 384))])
def test_cube_matches_blender(levels: int, counts: tuple) -> None:
    mesh = subdivide(polygons(CUBE_V, CUBE_F), levels)
    assert (len(mesh.positions), len(mesh.starts) - 1) == counts
    assert np.abs(mesh.positions).max() == pytest.approx(0.8395062, abs=1e-6)  # Blender: face centres 0.83950627
    corner = mesh.positions[np.argmax(mesh.positions.sum(axis=1))]
    assert np.allclose(corner, 0.5, atol=1e-7)  # Blender: (0.50000006, 0.5, 0.5) at every level


def test_without_limit_surface_and_simple() -> None:
    rough = subdivide(polygons(CUBE_V, CUBE_F), 2, limit=False)
    assert np.allclose(rough.positions[np.argmax(rough.positions.sum(axis=1))], 0.5092593, atol=1e-6)  # 0.50925934
    assert np.abs(rough.positions).max() == pytest.approx(0.8784722, abs=1e-6)  # Blender 0.87847233
    simple = subdivide(polygons(CUBE_V, CUBE_F), 2, limit=False, smooth=False)
    assert len(simple.positions) == 98 and np.allclose(np.abs(simple.positions).max(axis=1), 1.0)  # on the cube


def test_cylinder_with_ngon_caps_matches_blender() -> None:
    mesh = subdivide(polygons(CYLINDER_V, CYLINDER_F), 2)
    assert (len(mesh.positions), len(mesh.starts) - 1) == (290, 288)
    radius = np.hypot(mesh.positions[:, 0], mesh.positions[:, 1])
    assert mesh.positions[:, 2].max() == pytest.approx(0.9150333, abs=1e-6)  # the caps' centres
    assert radius.max() == pytest.approx(0.9022525, abs=1e-6)
    middle = np.abs(mesh.positions[:, 2]) < 1e-9
    assert radius[middle].min() == pytest.approx(0.8883559, abs=1e-6)


def test_open_box_and_plane_boundaries_match_blender() -> None:
    box = subdivide(polygons(CUBE_V, [f for f in CUBE_F if f != (1, 5, 7, 3)]), 2)
    assert (len(box.positions), len(box.starts) - 1) == (89, 80)
    assert np.allclose(box.positions.min(axis=0), [-0.9166667, -0.9166667, -0.8395063], atol=1e-6)
    assert np.allclose(box.positions.max(axis=0), [0.9166667, 0.9166667, 1.0], atol=1e-6)  # the open rim stays
    plane = subdivide(polygons([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)]), 2)
    xs = np.unique(np.round(np.abs(plane.positions[:, 0]), 5))
    # Blender: 0, 0.36458, 0.43056, 0.45833, 0.67188, 0.85417, 0.91667; its lone corners (valence-2 boundary
    # vertices, which OpenSubdiv refines 3 times) are 43/64 where the B-spline limit is 2/3 - at every level
    assert np.allclose(xs, [0.0, 0.36458, 0.43056, 0.45833, 43 / 64, 0.85417, 0.91667], atol=1e-5)
    for levels in (1, 3):
        corners = subdivide(polygons([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)]), levels)
        assert np.abs(corners.positions[:, 0]).max() == pytest.approx(0.9166667, abs=1e-6)  # edge midpoints
        assert np.sort(np.abs(corners.positions[:4, 0])) == pytest.approx([43 / 64] * 4, abs=1e-7)


def test_polygons_come_back_from_the_loaders_triangles() -> None:
    cube = from_parts([MeshObject("cube", CUBE_V, fan_triangles(CUBE_F))])
    assert sorted(cube.sizes.tolist()) == [4] * 6
    cylinder = from_parts([MeshObject("cylinder", CYLINDER_V, fan_triangles(CYLINDER_F))])
    assert sorted(cylinder.sizes.tolist()) == [4] * 12 + [12, 12]
    again = subdivide(cylinder, 2)
    assert (len(again.positions), len(again.starts) - 1) == (290, 288)
    assert again.positions[:, 2].max() == pytest.approx(0.9150333, abs=1e-6)
    normals = cylinder.polygon_normals()  # windings kept: caps face out
    assert np.allclose(sorted(normals[cylinder.sizes == 12][:, 2]), [-1, 1])
    ico = trimesh.creation.icosphere(1)
    assert np.all(from_parts([MeshObject("ico", ico.vertices, ico.faces)]).sizes == 3)  # no coplanar neighbours
    grid = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6), (4, 5, 8, 7)]  # 2 x 2 quads: an interior vertex, no fan
    flat = from_parts([MeshObject("grid", [(x, y, 0) for y in range(3) for x in range(3)], fan_triangles(grid))])
    assert sorted(flat.sizes.tolist()) == [4, 4, 4, 4]
    assert np.all(from_parts([MeshObject("cube", CUBE_V, fan_triangles(CUBE_F))], polygons=False).sizes == 3)
