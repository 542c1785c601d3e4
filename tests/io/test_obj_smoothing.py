"""OBJ faces in a smoothing group (``s 1``) without ``vn`` are shaded smooth as Blender 4.2's importer shades them
(hybridgen.io.obj_smoothing); the corner normals below were measured with bpy 4.2 (``wm.obj_import``, forward Y,
up Z) on ROOF: two roof halves meeting at a ridge, the back ridge vertex written twice (v 5 and v 7) so that each
half has its own - Blender keeps them apart, as it keeps every ``v`` line."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hybridgen.io.mesh_loader import load_objects
from hybridgen.io.obj_smoothing import smooth_objects

ROOF = """o Roof
v 0 0 0
v 1 0 0.5
v 2 0 0
v 0 1 0
v 1 1 0.5
v 2 1 0
v 1 1 0.5
{smooth}
f 1 2 5
f 1 5 4
f 2 3 6
f 2 6 7
"""
LEFT, RIGHT = (-0.447214, 0.0, 0.894427), (0.447214, 0.0, 0.894427)
RIDGE = (1.3e-05, 0.0, 1.0)  # the front ridge vertex: one left face (corner angle 63.4 deg), two right ones
BLENDER_CORNERS = [  # per face, per corner, as bpy 4.2 reports them
    [LEFT, RIDGE, LEFT], [LEFT, LEFT, LEFT], [RIDGE, RIGHT, RIGHT], [RIDGE, RIGHT, RIGHT]]


def _roof(tmp_path: Path, smooth: str) -> Path:
    path = tmp_path / "roof.obj"
    path.write_text(ROOF.format(smooth=smooth))
    return path


def test_smooth_group_without_normals_matches_blender(tmp_path):
    (roof,) = load_objects(_roof(tmp_path, "s 1"), up_axis="Z")
    assert roof.vertex_normals is not None
    corners = roof.vertex_normals[roof.faces]
    np.testing.assert_allclose(corners, np.array(BLENDER_CORNERS), atol=2e-5)


@pytest.mark.parametrize("smooth", ["s off", "s 0", ""])
def test_without_a_smoothing_group_faces_stay_flat(tmp_path, smooth):
    (roof,) = load_objects(_roof(tmp_path, smooth), up_axis="Z")
    assert roof.vertex_normals is None


def test_smoothing_groups_per_object(tmp_path):
    path = tmp_path / "mixed.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no A\ns 1\nf 1 2 3\no B\ns off\nf 1 2 3\no C\ns 2\n"
                    "f 1 2 3\ns off\nf 1 3 2\n")
    assert smooth_objects(path) == {None: False, "A": True, "B": False, "C": None}


def test_file_normals_win_over_the_group(tmp_path):
    path = tmp_path / "with_vn.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0.6 0.8\ns 1\nf 1//1 2//1 3//1\n")
    (obj,) = load_objects(path, up_axis="Z")
    np.testing.assert_allclose(obj.vertex_normals, [[0, 0.6, 0.8]] * 3, atol=1e-12)
