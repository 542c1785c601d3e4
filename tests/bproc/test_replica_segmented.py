"""bproc.loader.load_replica_segmented_mesh as BlenderProc 2.8 loads a Replica room's semantic mesh: one object per
object id the faces use (increasing), named by info_semantic.json (objects' class names over classes' names,
``undefined`` for an unknown id, Blender's suffixes for repeats), each face on its own corners (quads become two
triangles), its colors as linear vertex colors, no material; bad inputs are one line."""
from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture

HEADER = """ply
format binary_little_endian 1.0
element vertex {vertices}
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
element face {faces}
property list uchar int vertex_indices
property int object_id
end_header
"""


def _room(folder, quads: list[tuple[list[int], int]], vertices: np.ndarray, colors: np.ndarray) -> None:
    habitat = folder / "apartment_0" / "habitat"
    habitat.mkdir(parents=True)
    (habitat / "info_semantic.json").write_text(json.dumps({
        "classes": [{"id": 5, "name": "wall"}, {"id": 9, "name": "floor"}],
        "objects": [{"id": 9, "class_name": "chair"}, {"id": 12, "class_name": "chair"}]}))
    with open(habitat / "mesh_semantic.ply", "wb") as handle:
        handle.write(HEADER.format(vertices=len(vertices), faces=len(quads)).encode())
        for vertex, color in zip(vertices, colors):
            handle.write(struct.pack("<6f3B", *vertex, 0.0, 0.0, 1.0, *color))
        for corners, object_id in quads:
            handle.write(struct.pack("<B4ii", 4, *corners, object_id))


def test_objects_per_id(bproc, tmp_path) -> None:  # noqa: F811
    grid = np.array([[x, y, 0.0] for y in range(3) for x in range(4)], np.float32)  # 4 x 3 vertices, 1 m apart
    colors = np.array([[10 * i, 255 - 10 * i, 128] for i in range(len(grid))], np.uint8)

    def quad(x: int, y: int) -> list[int]:
        return [y * 4 + x, y * 4 + x + 1, (y + 1) * 4 + x + 1, (y + 1) * 4 + x]

    quads = [(quad(0, 0), 12), (quad(1, 0), 5), (quad(2, 0), 12), (quad(0, 1), 9), (quad(1, 1), 40)]
    _room(tmp_path, quads, grid, colors)
    objects = bproc.loader.load_replica_segmented_mesh(str(tmp_path), "apartment_0")
    assert [o.get_name() for o in objects] == ["wall", "chair", "chair.001", "undefined"]  # ids 5, 9, 12, 40
    by_id = dict(zip((5, 9, 12, 40), objects))
    for object_id, obj in by_id.items():
        corners = [c for c, i in quads if i == object_id]
        (part,) = obj.parts
        assert len(part.vertices) == 4 * len(corners) and len(part.faces) == 2 * len(corners)
        assert np.allclose(part.vertices, grid[np.concatenate(corners)])
        assert obj.mesh_as_trimesh().area == pytest.approx(len(corners))  # unit quads, both triangles
        encoded = colors[np.concatenate(corners)] / 255.0
        assert np.allclose(part.vertex_colors, np.where(encoded <= 0.04045, encoded / 12.92,
                                                        ((encoded + 0.055) / 1.055) ** 2.4))
        assert obj.get_materials() == []
    with pytest.raises(InputError, match='The dataset folder: ".*apartment_1" does not exist!'):
        bproc.loader.load_replica_segmented_mesh(str(tmp_path), "apartment_1")
    (tmp_path / "apartment_0" / "habitat" / "mesh_semantic.ply").write_text("ply\nformat ascii 1.0\nend_header\n")
    with pytest.raises(InputError, match="is not a Replica semantic mesh"):
        bproc.loader.load_replica_segmented_mesh(str(tmp_path), "apartment_0")
