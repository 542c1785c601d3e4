"""The NumPy primitive meshes are trimesh.creation's arrays bit for bit (trimesh is the independent oracle here),
closed volumes of the analytic size, and building primitives does not import trimesh."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import trimesh

from hybridgen.scene import primitive_meshes
from hybridgen.scene.closed_volume import is_closed_volume, signed_volume
from hybridgen.scene.primitives import PRIMITIVES, make_primitive
from hybridgen.scene.vertex_normals import angle_weighted_normals

SIZES = (1.0, 0.7, 2.0, 0.123, 0.03, 6.0, 37.5)

TRIMESH_BUILDERS = {
    "cube": lambda size: trimesh.creation.box(extents=[size] * 3),
    "sphere": lambda size: trimesh.creation.icosphere(subdivisions=4, radius=size / 2),
    "cylinder": lambda size: trimesh.creation.cylinder(radius=size / 2, height=size, sections=64),
    "cone": lambda size: trimesh.creation.cone(radius=size / 2, height=size, sections=64),
    "torus": lambda size: trimesh.creation.torus(major_radius=size * 0.35, minor_radius=size * 0.15),
    "plane": lambda size: trimesh.Trimesh(
        vertices=np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64) * size / 2,
        faces=np.array([[0, 1, 2], [0, 2, 3]])),
}


def _assert_same_arrays(ours: tuple[np.ndarray, np.ndarray], theirs: trimesh.Trimesh) -> None:
    vertices, faces = ours
    expected_vertices, expected_faces = np.asarray(theirs.vertices), np.asarray(theirs.faces)
    assert vertices.dtype == expected_vertices.dtype == np.float64
    assert faces.dtype == expected_faces.dtype
    assert np.array_equal(vertices, expected_vertices)  # same bits, same vertex order
    assert np.array_equal(faces, expected_faces)  # same face order and winding


def test_every_primitive_has_a_trimesh_oracle() -> None:
    assert set(PRIMITIVES) == set(TRIMESH_BUILDERS)


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("shape", sorted(TRIMESH_BUILDERS))
def test_primitive_equals_trimesh_creation(shape: str, size: float) -> None:
    _assert_same_arrays(PRIMITIVES[shape](size), TRIMESH_BUILDERS[shape](size))


@pytest.mark.parametrize("subdivisions,radius", [(0, 1.0), (1, 0.5), (2, 3.0), (3, 0.25)])
def test_icosphere_other_subdivisions_equal_trimesh(subdivisions: int, radius: float) -> None:
    _assert_same_arrays(primitive_meshes.icosphere(subdivisions, radius),
                        trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius))


@pytest.mark.parametrize("sections", [3, 7, 32])
def test_revolved_shapes_other_sections_equal_trimesh(sections: int) -> None:
    _assert_same_arrays(primitive_meshes.cylinder(0.4, 1.3, sections),
                        trimesh.creation.cylinder(radius=0.4, height=1.3, sections=sections))
    _assert_same_arrays(primitive_meshes.cone(0.4, 1.3, sections),
                        trimesh.creation.cone(radius=0.4, height=1.3, sections=sections))
    _assert_same_arrays(primitive_meshes.torus(1.0, 0.2, sections, sections + 5),
                        trimesh.creation.torus(1.0, 0.2, major_sections=sections, minor_sections=sections + 5))


@pytest.mark.parametrize("size", SIZES)
def test_torus_vertex_normals_equal_trimesh(size: float) -> None:
    obj = make_primitive("torus", size)
    expected = np.asarray(TRIMESH_BUILDERS["torus"](size).vertex_normals)
    assert np.array_equal(obj.vertex_normals, expected)


def test_angle_weighted_normals_ignore_degenerate_faces_as_trimesh_does() -> None:
    vertices, faces = primitive_meshes.box((1.0, 2.0, 0.5))
    faces = np.concatenate([faces, [[0, 0, 1], [2, 2, 2]]])  # two zero-area faces
    expected = trimesh.Trimesh(vertices, faces, process=False).vertex_normals
    assert np.array_equal(angle_weighted_normals(vertices, faces), expected)


@pytest.mark.parametrize("size", [1.0, 0.3])
def test_solid_primitives_are_closed_with_their_analytic_volume(size: float) -> None:
    r = size / 2
    exact = {"cube": size ** 3, "sphere": 4 / 3 * np.pi * r ** 3, "cylinder": np.pi * r ** 2 * size,
             "cone": np.pi * r ** 2 * size / 3, "torus": 2 * np.pi ** 2 * (0.35 * size) * (0.15 * size) ** 2}
    # inscribed polyhedra: the faceting loses at most this fraction of the volume
    faceting = {"cube": 1e-12, "sphere": 0.01, "cylinder": 0.002, "cone": 0.002, "torus": 0.02}
    for shape, volume in exact.items():
        vertices, faces = PRIMITIVES[shape](size)
        assert is_closed_volume(vertices, faces), shape
        enclosed = signed_volume(vertices[faces])
        assert volume * (1 - faceting[shape]) <= enclosed <= volume * (1 + 1e-12), shape


def test_plane_is_an_upward_square() -> None:
    vertices, faces = PRIMITIVES["plane"](4.0)
    assert np.array_equal(vertices[:, :2].min(axis=0), [-2.0, -2.0])
    assert np.array_equal(vertices[:, :2].max(axis=0), [2.0, 2.0])
    edges = vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]
    assert np.all(np.cross(*edges)[:, 2] > 0)  # faces +Z


def test_a_millimetre_torus_keeps_its_faces() -> None:
    """trimesh drops every face of a 1 mm torus (its 1e-8 m^2 area cut); ours stays a closed volume."""
    vertices, faces = PRIMITIVES["torus"](1e-3)
    assert len(faces) == 2048 and len(vertices) == 1024
    assert is_closed_volume(vertices, faces)


def test_building_every_primitive_does_not_import_trimesh() -> None:
    code = ("import sys, json, hybridgen\n"
            f"for shape in {sorted(PRIMITIVES)!r}:\n"
            "    hybridgen.make_primitive(shape, 0.5)\n"
            "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] == 'trimesh')))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert json.loads(result.stdout.strip().splitlines()[-1]) == []
