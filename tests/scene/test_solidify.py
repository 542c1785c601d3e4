"""Blender's Solidify modifier (hybridgen.scene.solidify) against analytic shells and Blender 4.2's results measured
with bpy 4.2 by tools/blender_modifiers.py (its meshes: a 1 m square, the 2 m cube without its +x face, an
irregular open fan whose apex polygons differ in angle and area)."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from hybridgen.scene.mesh_object import MeshObject
from hybridgen.scene.polygon_mesh import PolygonMesh, from_parts
from hybridgen.scene.solidify import solidify

CUBE_V = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
OPEN_BOX_F = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4)]
TENT_V = [(0, 0, 0.6), (-1, -0.7, 0), (1.3, -1, 0), (0.8, 1.1, 0.2), (-1.2, 0.9, -0.1)]
TENT_F = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 1)]
BLENDER_TENT_INNER = [(0.01238, 0.01294, 0.4008), (-0.92994, -0.64627, -0.17946), (1.25796, -0.94251, -0.18689),
                      (0.77298, 1.04993, 0.00826), (-1.12652, 0.85718, -0.28102)]
"""Blender's new vertices of the fan at thickness 0.2 (the originals stay): v - 0.2 n, n its vertex normal."""


def polygons(vertices: list, faces: list) -> PolygonMesh:
    return PolygonMesh(np.array(vertices, float), np.array([i for f in faces for i in f]),
                       np.cumsum([0] + [len(f) for f in faces]), np.zeros(len(faces), int))


def as_trimesh(mesh: PolygonMesh) -> trimesh.Trimesh:
    triangles, _ = mesh.fan_triangles()
    return trimesh.Trimesh(mesh.positions, mesh.corners[triangles], process=False)


@pytest.mark.parametrize("thickness", [0.1, 0.0025])
def test_unit_square_becomes_a_closed_box(thickness: float) -> None:
    square = MeshObject("square", [(-0.5, -0.5, 0), (0.5, -0.5, 0), (0.5, 0.5, 0), (-0.5, 0.5, 0)], [(0, 1, 2), (0, 2, 3)])
    shell = solidify(from_parts([square]), thickness)
    assert len(shell.positions) == 8 and np.all(shell.sizes == 4) and len(shell.sizes) == 6  # Blender: 8 / 6
    assert sorted(set(shell.positions[:, 2].round(12))) == [-thickness, 0.0]  # offset -1: behind the surface
    closed = as_trimesh(shell)
    assert closed.is_watertight and closed.is_winding_consistent
    assert closed.volume == pytest.approx(thickness, rel=1e-9)  # positive: faces point out
    part, = shell.to_parts([square])
    assert trimesh.Trimesh(part.vertices, part.faces).is_watertight


def test_open_box_matches_blender() -> None:
    shell = solidify(polygons(CUBE_V, OPEN_BOX_F), 0.1)
    assert (len(shell.positions), len(shell.sizes)) == (16, 14)  # Blender: 16 vertices, 10 shell + 4 rim quads
    inner = shell.positions[8:]
    assert np.allclose(inner[0], [-0.94226, -0.94226, -0.94226], atol=1e-5)  # 0.1 along (1, 1, 1) / sqrt 3
    assert np.allclose(inner[1], [-0.92929, -0.92929, 1.0], atol=1e-5)  # a rim vertex: 2 faces
    assert as_trimesh(shell).is_watertight
    even = solidify(polygons(CUBE_V, OPEN_BOX_F), 0.1, offset=0.3, use_even_offset=True)
    # Blender, offset 0.3 and even thickness: the faces move 0.065 out and 0.035 in, corners included
    assert np.allclose(np.abs(even.positions[:8]).max(axis=1), 1.065, atol=1e-5)
    assert np.allclose(np.abs(even.positions[8:]).max(axis=1)[[0, 2]], 0.965, atol=1e-5)


def test_irregular_fan_matches_blender() -> None:
    shell = solidify(polygons(TENT_V, TENT_F), 0.2)
    assert (len(shell.positions), len(shell.sizes)) == (10, 12)
    assert np.allclose(shell.positions[:5], TENT_V) and np.allclose(shell.positions[5:], BLENDER_TENT_INNER, atol=2e-5)
    no_rim = solidify(polygons(TENT_V, TENT_F), 0.2, use_rim=False)
    assert len(no_rim.sizes) == 8
    flipped = solidify(polygons(TENT_V, TENT_F), 0.2, use_flip_normals=True)
    assert as_trimesh(flipped).volume == pytest.approx(-as_trimesh(shell).volume)
