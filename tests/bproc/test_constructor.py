"""bproc.constructor.construct_random_room against analytic truth: the floor's area is the asked one, the walls
stand 0..wall_height around it, BlenderProc's return order and material rules, and every placed cube stands on the
floor (z = 0, turned about Z only) inside the plan without touching another (2D separating axes of the squares)."""
from __future__ import annotations

import random

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture

CUBE = 0.5


def _room(bproc, seed: int, **kwargs):  # noqa: F811
    random.seed(seed)
    cubes = [bproc.object.create_primitive("CUBE", size=CUBE) for _ in range(3)]
    materials = [bproc.material.create("bricks"), bproc.material.create("wood")]
    return cubes, materials, bproc.constructor.construct_random_room(12.0, cubes, materials, **kwargs)


def _triangle_area(vertices: np.ndarray, faces: np.ndarray) -> float:
    tri = vertices[faces]
    return float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum() / 2)


def _inside_floor(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Which 2D points lie in (or on) a floor triangle (barycentric test)."""
    a, b, c = (vertices[faces][:, k, :2] for k in range(3))
    inside = np.zeros(len(points), bool)
    for p_index, p in enumerate(points):
        v0, v1, v2 = c - a, b - a, p - a
        den = v0[:, 0] * v1[:, 1] - v1[:, 0] * v0[:, 1]
        u = (v2[:, 0] * v1[:, 1] - v1[:, 0] * v2[:, 1]) / den
        v = (v0[:, 0] * v2[:, 1] - v2[:, 0] * v0[:, 1]) / den
        inside[p_index] = np.any((u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9))
    return inside


def _squares_overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Separating axis test of two convex 2D quads (4, 2)."""
    for quad in (a, b):
        for k in range(4):
            edge = quad[(k + 1) % 4] - quad[k]
            axis = np.array([-edge[1], edge[0]])
            pa, pb = a @ axis, b @ axis
            if pa.max() <= pb.min() + 1e-9 or pb.max() <= pa.min() + 1e-9:
                return False
    return True


def test_room_geometry_order_and_materials(bproc) -> None:  # noqa: F811
    cubes, materials, objects = _room(bproc, 3, amount_of_extrusions=2, wall_height=2.7)
    names = [obj.get_name() for obj in objects]
    assert names[:2] == ["Wall", "Ceiling"] and names[-1] == "Floor"
    wall, ceiling, floor = objects[0], objects[1], objects[-1]
    assert _triangle_area(*floor.world_triangles()) == pytest.approx(12.0)
    assert _triangle_area(*ceiling.world_triangles()) == pytest.approx(12.0)
    wall_vertices = wall.world_triangles()[0]
    assert wall_vertices[:, 2].min() == 0.0 and wall_vertices[:, 2].max() == pytest.approx(2.7)
    assert floor.get_materials()[0] in materials and wall.get_materials()[0] in materials
    assert not ceiling.has_materials()  # assign_material_to_ceiling is False by default
    # everything else was deleted: the session holds exactly the returned mesh objects
    assert set(bproc.object.get_all_mesh_objects()) == set(objects)
    assert all(cube.is_valid() == (cube in objects) for cube in cubes)


def test_placed_objects_stand_inside_the_room_apart(bproc) -> None:  # noqa: F811
    _, _, objects = _room(bproc, 5, amount_of_extrusions=1, amount_of_objects_per_sq_meter=1.0)
    floor, placed = objects[-1], objects[2:-1]
    assert len(placed) >= 3
    floor_vertices, floor_faces = floor.world_triangles()
    footprints = []
    for obj in placed:
        assert obj.get_location()[2] == 0.0
        np.testing.assert_allclose(obj.get_rotation_euler()[:2], 0.0, atol=1e-12)
        corners = obj.get_bound_box()[[0, 3, 7, 4], :2]  # the bottom square in Blender's corner order
        assert _inside_floor(corners, floor_vertices, floor_faces).all()
        footprints.append(corners)
    for i in range(len(footprints)):
        for j in range(i):
            assert not _squares_overlap(footprints[i], footprints[j])


def test_same_seed_same_room_and_no_ceiling_when_asked(bproc) -> None:  # noqa: F811
    first = [obj.get_local2world_mat() for obj in _room(bproc, 9, amount_of_extrusions=1)[2]]
    from hybridgen.bproc.session import reset

    reset()
    again = _room(bproc, 9, amount_of_extrusions=1, create_ceiling=False)[2]
    assert "Ceiling" not in [obj.get_name() for obj in again]
    # the ceiling draws no random value: the rest of the room is the same
    np.testing.assert_allclose([obj.get_local2world_mat() for obj in again], [first[0]] + first[2:])
