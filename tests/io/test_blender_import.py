"""Mesh files load as Blender's importers (which BlenderProc uses) load them: OBJ +Y up turned to +Z up,
one object per ``o`` with Blender's names and its own materials; PLY as stored; ``up_axis`` overrides."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.io.mesh_loader import blender_name, unique_blender_name

# Three `o` objects over two shared materials; `o Cone` comes twice (Blender merges the sections), and the
# first face comes before any `o` (Blender names that object after the file).
OBJ = """mtllib shared.mtl
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
v 2 0 0
v 2 1 0
v 2 0 1
usemtl red
f 1 2 3
o Cube
usemtl red
f 1 2 4
o Cube.001
usemtl blue
f 5 6 7
o Cone
usemtl blue
f 1 3 4
o   Long   name
usemtl red
f 2 3 4
o Cone
usemtl red
f 5 7 6
"""
MTL = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n"


@pytest.fixture()
def shared_obj(tmp_path):
    (tmp_path / "shared.mtl").write_text(MTL)
    path = tmp_path / "shared.obj"
    path.write_text(OBJ)
    return path


def test_one_object_per_o_with_blender_names_and_own_materials(shared_obj):
    objects = hg.load_objects(shared_obj)
    names = [o.name for o in objects]
    # file order; the faces before any `o` form an object named after the file; repeated `o Cone` is one
    # Blender object whose two materials make two hybridgen objects of that name
    assert names == ["shared", "Cube", "Cube.001", "Cone", "Cone", "Long name"]
    by_name = {}
    for obj in objects:
        by_name.setdefault(obj.name, []).append(obj)
    assert by_name["Cube"][0].material.name == "red" and by_name["Cube.001"][0].material.name == "blue"
    assert sorted(o.material.name for o in by_name["Cone"]) == ["blue", "red"]
    assert sorted(o.attributes["material_part"] for o in by_name["Cone"]) == ["blue", "red"]
    assert "material_part" not in by_name["Cube"][0].attributes
    np.testing.assert_allclose(by_name["Cube"][0].material.base_color[:3], [1, 0, 0])
    assert [len(o.faces) for o in objects] == [1, 1, 1, 1, 1, 1]


def test_obj_is_y_up_like_blenders_importer(shared_obj):
    # Blender: axis_forward -Z, axis_up Y -> file (x, y, z) is world (x, -z, y); the turn is in the vertices
    (cube,) = [o for o in hg.load_objects(shared_obj) if o.name == "Cube"]
    file_vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1]], float)  # f 1 2 4
    expected = file_vertices[:, [0, 2, 1]] * [1, -1, 1]
    np.testing.assert_allclose(np.sort(cube.world_vertices(), axis=0), np.sort(expected, axis=0), atol=1e-12)
    np.testing.assert_allclose(cube.local2world, np.eye(4))
    # the explicit override reads the file as stored
    (stored,) = [o for o in hg.load_objects(shared_obj, up_axis="Z") if o.name == "Cube"]
    np.testing.assert_allclose(np.sort(stored.world_vertices(), axis=0), np.sort(file_vertices, axis=0))


def test_y_up_floor_becomes_horizontal_with_normal_up(tmp_path):
    # a floor modelled in a Y-up tool: normal +Y in the file
    (tmp_path / "floor.obj").write_text("o Plane\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nvn 0 1 0\n"
                                        "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")
    (floor,) = hg.load_objects(tmp_path / "floor.obj")
    assert floor.name == "Plane"
    np.testing.assert_allclose(floor.world_vertices()[:, 2], 0.0, atol=1e-12)
    np.testing.assert_allclose(floor.face_normals, [[0, 0, 1], [0, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(floor.vertex_normals, np.tile([0, 0, 1.0], (4, 1)), atol=1e-12)


def test_ply_and_stl_are_read_as_stored(tmp_path):
    mesh = trimesh.creation.box(extents=[1.0, 2.0, 3.0])
    for suffix in (".ply", ".stl"):
        mesh.export(tmp_path / f"box{suffix}")
        (obj,) = hg.load_objects(tmp_path / f"box{suffix}")
        np.testing.assert_allclose(np.ptp(obj.world_vertices(), axis=0), [1.0, 2.0, 3.0], atol=1e-6)


def test_blender_names_and_clashes():
    assert blender_name("  Long \t name ") == "Long name"
    assert len(blender_name("x" * 100).encode()) == 63
    assert unique_blender_name("Cube", ["Sphere"]) == "Cube"
    assert unique_blender_name("Cube", ["Cube"]) == "Cube.001"
    assert unique_blender_name("Cube", ["Cube", "Cube.001"]) == "Cube.002"
    assert unique_blender_name("Cube.001", ["Cube", "Cube.001"]) == "Cube.002"


def test_loading_twice_gives_blender_suffixes(shared_obj, tmp_path):
    from hybridgen.config.config_file import load_config
    from hybridgen.run.pipeline import build_modules, execute

    config = tmp_path / "twice.yaml"
    config.write_text(f"modules:\n  - name: main.Initializer\n"
                      f"  - name: loader.ObjLoader\n    config: {{path: {shared_obj}}}\n"
                      f"  - name: loader.ObjLoader\n    config: {{path: {shared_obj}}}\n")
    loaded = load_config(config)
    context = execute(loaded, build_modules(loaded))
    names = [o.name for o in context.scene.objects]
    assert names[:6] == ["shared", "Cube", "Cube.001", "Cone", "Cone", "Long name"]
    # second copy: each Blender object gets the next free .NNN (both Cone parts the same one)
    assert names[6:] == ["shared.001", "Cube.002", "Cube.003", "Cone.001", "Cone.001", "Long name.001"]
