"""bproc.utility.UndoAfterExecution: what a block changes (poses, keyframes, custom properties, sliced meshes,
material values, new and deleted objects, camera poses, renderer settings) is back when it ends, in the objects
the script held; join_with_other_objects, which the same examples use to put sliced surfaces back."""
from __future__ import annotations

import numpy as np

from writer_session import bproc  # noqa: F401 - the fixture


def test_a_block_is_undone_in_place(bproc) -> None:  # noqa: F811
    table = bproc.object.create_primitive("CUBE", location=[1.0, 2.0, 0.5])
    table.set_cp("category_id", 4)
    material = bproc.material.create("wood")
    material.set_principled_shader_value("Roughness", 0.25)
    table.add_material(material)
    lamp = bproc.object.create_primitive("SPHERE")
    bproc.camera.add_camera_pose(np.eye(4))
    faces_before = len(table.local_mesh()[1])
    with bproc.utility.UndoAfterExecution():
        surface = bproc.object.slice_faces_with_normals(table)
        table.set_location([5.0, 5.0, 5.0], frame=3)
        table.set_cp("category_id", 9)
        material.set_principled_shader_value("Roughness", 0.9)
        lamp.delete()
        extra = bproc.object.create_primitive("PLANE")
        bproc.camera.add_camera_pose(np.eye(4))
        bproc.renderer.set_max_amount_of_samples(7)
        assert len(table.local_mesh()[1]) == faces_before - 2 and surface.is_valid()
    np.testing.assert_allclose(table.get_location(), [1.0, 2.0, 0.5])
    np.testing.assert_allclose(table.get_location(frame=3), [1.0, 2.0, 0.5])  # the key is gone too
    assert table.get_cp("category_id") == 4 and len(table.local_mesh()[1]) == faces_before
    assert material.get_principled_shader_value("Roughness") == 0.25
    assert lamp.is_valid() and not extra.is_valid() and not surface.is_valid()
    assert bproc.object.get_all_mesh_objects() == [table, lamp]
    assert bproc.utility.num_frames() == 1 and bproc.object.create_primitive("PLANE").get_name() == "Plane"
    from hybridgen.bproc.session import SESSION

    assert SESSION.renderer.samples == 1024


def test_perform_undo_op_false_keeps_changes(bproc) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE")
    with bproc.utility.UndoAfterExecution(perform_undo_op=False):
        cube.set_location([0.0, 0.0, 3.0])
    np.testing.assert_allclose(cube.get_location(), [0.0, 0.0, 3.0])


def test_join_keeps_world_geometry_and_materials(bproc) -> None:  # noqa: F811
    top = bproc.object.create_primitive("CUBE", size=1.0, location=[0.0, 0.0, 1.0], rotation=[0.0, 0.0, 0.4])
    leg = bproc.object.create_primitive("CUBE", size=0.5, location=[2.0, 0.0, 0.0], scale=[1.0, 1.0, 3.0])
    wood, steel = bproc.material.create("wood"), bproc.material.create("steel")
    top.add_material(wood)
    leg.add_material(steel)
    before = np.concatenate([top.world_triangles()[0], leg.world_triangles()[0]])
    top.join_with_other_objects([leg])
    assert not leg.is_valid() and bproc.object.get_all_mesh_objects() == [top]
    np.testing.assert_allclose(top.world_triangles()[0], before, atol=1e-12)
    assert top.get_materials() == [wood, steel]
    assert [top.part_material(i).name for i in range(2)] == ["wood", "steel"]
