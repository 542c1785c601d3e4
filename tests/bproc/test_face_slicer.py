"""bproc.object.extract_floor / slice_faces_with_normals and the 1D mean shift under them, on hand-built meshes
whose floor, ceiling and table-top faces are known: which faces move, where they go (name, material slot, pose),
what stays."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.scene.mean_shift import mean_shift_1d
from writer_session import bproc  # noqa: F401 - the fixture


def _quad(z: float, size: float, up: bool, x0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x0, 0, z], [x0 + size, 0, z], [x0 + size, size, z], [x0, size, z]], dtype=np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3]]) if up else np.array([[0, 2, 1], [0, 3, 2]])
    return v, faces


def _object(bproc, name: str, quads: list[list[tuple[np.ndarray, np.ndarray]]], location=(0.0, 0.0, 0.0)):  # noqa: F811
    """A mesh object with one part per list of quads, a material per part."""
    from hybridgen.scene.mesh_object import MeshObject as ScenePart

    parts = []
    for index, group in enumerate(quads):
        vertices, faces = [], []
        for v, f in group:
            faces.append(f + sum(len(x) for x in vertices))
            vertices.append(v)
        parts.append(ScenePart(f"{name}{index}", np.concatenate(vertices), np.concatenate(faces)))
    obj = bproc.types.MeshObject(name, parts, [bproc.material.create(f"mat{i}") for i in range(len(parts))])
    obj.set_location(location)
    return obj


def _heights(obj) -> list[float]:
    vertices, faces = obj.world_triangles()
    return sorted(set(np.round(vertices[faces].mean(axis=1)[:, 2], 6).tolist()))


def test_mean_shift_clusters_of_heights() -> None:
    centres, labels = mean_shift_1d(np.array([0.0, 0.01, 0.02, 2.5, 2.51, 0.015]), 0.2)
    np.testing.assert_allclose(centres, [0.01125, 2.505])  # the larger cluster first
    assert labels.tolist() == [0, 0, 0, 1, 1, 0]
    centres, _ = mean_shift_1d(np.array([0.0, 0.1, 0.25]), 0.2)  # one mode: both seeds climb to 0.1167
    np.testing.assert_allclose(centres, [0.35 / 3])


def test_extract_floor_moves_the_lowest_level_faces(bproc) -> None:  # noqa: F811
    room = _object(bproc, "Room", [[_quad(0.0, 4, True), _quad(0.5, 1, True, 5)],
                                   [_quad(2.5, 4, False)]], location=(1.0, 2.0, -0.2))
    room.set_cp("category_id", 3)
    floors = bproc.object.extract_floor([room], new_name_for_object="floor")
    assert [f.get_name() for f in floors] == ["floor"]
    floor = floors[0]
    assert _heights(floor) == [-0.2]  # the platform at 0.3 m is its own cluster
    assert _heights(room) == [0.3, 2.3]
    np.testing.assert_allclose(floor.get_location(), [1.0, 2.0, -0.2])
    assert floor.get_cp("category_id") == 3 and floor.part_material(0).name == "mat0"
    ceilings = bproc.object.extract_floor([room], new_name_for_object="ceiling", up_vector_upwards=False)
    assert _heights(ceilings[0]) == [2.3] and ceilings[0].part_material(0).name == "mat1"
    assert _heights(room) == [0.3]
    assert bproc.object.extract_floor([room], new_name_for_object="Floor",
                                      should_skip_if_object_is_already_there=True) == []


def test_extract_floor_with_a_height_list(bproc, tmp_path) -> None:  # noqa: F811
    room = _object(bproc, "Room", [[_quad(0.0, 4, True), _quad(0.5, 1, True, 5), _quad(2.0, 1, True, 7)]])
    (tmp_path / "heights.txt").write_text("[0.5, 2.0]")
    assert bproc.object.extract_floor([room], height_list_path=str(tmp_path / "heights.txt")) == []
    copy = bproc.filter.one_by_attr(bproc.object.get_all_mesh_objects(), "name", "Room.001")
    assert _heights(copy) == [0.5, 2.0] and _heights(room) == [0.0]


def test_slice_faces_with_normals_takes_the_largest_level(bproc) -> None:  # noqa: F811
    table = _object(bproc, "Table", [[_quad(0.3, 0.5, True), _quad(0.7, 1.0, True, 2), _quad(0.0, 1.0, False, 4)]])
    up = np.array([0.0, 0.0, 2.0])
    top = bproc.object.slice_faces_with_normals(table, up_vector_upwards=up)
    assert top.get_name() == "Surface" and _heights(top) == [0.7] and _heights(table) == [0.0, 0.3]
    np.testing.assert_allclose(up, [0, 0, 1])  # normalized in place, as BlenderProc does
    with pytest.raises(Exception, match="no face"):
        bproc.object.slice_faces_with_normals(table, up_vector_upwards=np.array([1.0, 0.0, 0.0]))
