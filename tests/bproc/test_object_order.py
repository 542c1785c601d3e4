"""bproc.loader.load_obj returns an OBJ's objects in Blender 4.2's order (by name, not the file's), so a seeded
script that samples a pose per object gives each draw to the object BlenderProc gives it."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from writer_session import bproc  # noqa: F401 - the fixture

FILE_ORDER = ["Zeta", "alpha", "Beta", "item10", "item2", "Cube.001", "Cube", "cube", "Item1", "_x", "a.2",
              "Cube.010", "Cube.002", "b_2", "B1"]
# Measured with bpy 4.2.0: bpy.ops.wm.obj_import of this file, bpy.context.selected_objects' names after the
# first import, and (without the first import's objects) after a second import of the same file.
BLENDER_ORDER = ["_x", "a.2", "alpha", "B1", "b_2", "Beta", "Cube", "cube", "Cube.001", "Cube.002", "Cube.010",
                 "Item1", "item10", "item2", "Zeta"]
SECOND_IMPORT = ["_x.001", "a.001", "alpha.001", "B1.001", "b_2.001", "Beta.001", "Cube.003", "cube.001",
                 "Cube.004", "Cube.005", "Cube.006", "Item1.001", "item10.001", "item2.001", "Zeta.001"]


def _write_obj(path: Path) -> Path:
    """One triangle per ``o`` name, at x = its 1-based position in the file."""
    lines = []
    for index, name in enumerate(FILE_ORDER, 1):
        first = 3 * index - 2
        lines += [f"o {name}", f"v {index} 0 0", f"v {index} 1 0", f"v {index} 0 1",
                  f"f {first} {first + 1} {first + 2}"]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_load_obj_returns_blenders_order_and_names(bproc, tmp_path):
    path = _write_obj(tmp_path / "order.obj")
    first = bproc.loader.load_obj(str(path))
    assert [obj.get_name() for obj in first] == BLENDER_ORDER
    second = bproc.loader.load_obj(str(path))
    assert [obj.get_name() for obj in second] == SECOND_IMPORT
    assert bproc.object.get_all_mesh_objects() == first + second


def test_seeded_pose_sampling_follows_blenders_order(bproc, tmp_path):
    objects = bproc.loader.load_obj(str(_write_obj(tmp_path / "order.obj")))

    def sample_pose(obj: Any) -> None:
        obj.set_location(np.random.uniform([-10, -10, 0], [10, 10, 5]))

    np.random.seed(7)
    result = bproc.object.sample_poses(objects, sample_pose, objects_to_check_collisions=[])
    assert all(placed for _, placed in result.values())
    np.random.seed(7)
    draws = {name: np.random.uniform([-10, -10, 0], [10, 10, 5]) for name in BLENDER_ORDER}
    for obj in objects:
        np.testing.assert_allclose(obj.get_location(), draws[obj.get_name()], atol=1e-12)
    by_name = {obj.get_name(): obj for obj in objects}
    np.testing.assert_allclose(by_name["Beta"].get_location(), draws["Beta"])
    assert not np.allclose(by_name["Beta"].get_location(), list(draws.values())[FILE_ORDER.index("Beta")])
