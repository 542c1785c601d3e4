"""Mesh files of every supported format load with the right geometry, frames, normals and names."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.errors import InputError


def _asymmetric_mesh() -> trimesh.Trimesh:
    """A box stretched differently along x, y, z, so any axis swap shows in the bounds."""
    return trimesh.creation.box(extents=[1.0, 2.0, 3.0], transform=trimesh.transformations.translation_matrix(
        [0.5, 1.0, 1.5]))


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".off", ".glb"])
def test_formats_load_with_same_world_geometry(tmp_path, suffix):
    mesh = _asymmetric_mesh()
    path = tmp_path / f"box{suffix}"
    mesh.export(path)
    pose = hg.object_pose([1, 2, 3], [0, 0, np.pi / 2], 2.0)
    # OBJ and glTF files are +Y up (Blender's importers); the loader turns them to +Z up unless told otherwise
    objects = hg.load_objects(path, name="b", category_id=7, local2world=pose,
                              up_axis="Z" if suffix in (".glb", ".obj") else "auto")
    assert len(objects) == 1 and objects[0].name == "b" and objects[0].category_id == 7
    world = objects[0].world_vertices()
    expected = mesh.vertices @ (pose[:3, :3].T) + pose[:3, 3]
    np.testing.assert_allclose(world.min(0), expected.min(0), atol=1e-5)
    np.testing.assert_allclose(world.max(0), expected.max(0), atol=1e-5)


def test_gltf_y_up_becomes_z_up(tmp_path):
    mesh = _asymmetric_mesh()  # in the file, +Y is up: the 2 m extent
    path = tmp_path / "box.glb"
    mesh.export(path)
    (obj,) = hg.load_objects(path)
    extent = np.ptp(obj.world_vertices(), axis=0)
    np.testing.assert_allclose(extent, [1.0, 3.0, 2.0], atol=1e-6)  # file Y (2 m) is now world Z


def test_obj_with_normals_materials_and_parts(tmp_path):
    (tmp_path / "two.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl green\nKd 0 1 0\n")
    (tmp_path / "two.obj").write_text(
        "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\n"
        "usemtl red\nf 1//1 2//1 3//1\nusemtl green\nf 2//1 4//1 3//1\n")
    objects = hg.load_objects(tmp_path / "two.obj", name="pair", category_id=1)
    # one Blender object with two materials: one hybridgen object per material, both with the object's name
    assert len(objects) == 2
    assert [o.name for o in objects] == ["pair", "pair"]
    assert sorted(o.attributes["material_part"] for o in objects) == ["green", "red"]
    assert all(o.vertex_normals is not None for o in objects)
    colors = sorted(tuple(np.round(o.material.base_color[:3], 3)) for o in objects)
    assert colors == [(0.0, 1.0, 0.0), (1.0, 0.0, 0.0)]


def test_flat_mesh_has_no_vertex_normals(tmp_path):
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (obj,) = hg.load_objects(tmp_path / "tri.obj")
    assert obj.vertex_normals is None and obj.name == "tri"
    np.testing.assert_allclose(obj.face_normals, [[0, -1, 0]], atol=1e-12)  # file +Z is Blender's -Y (Y-up OBJ)


def test_unsupported_and_bad_indices(tmp_path):
    (tmp_path / "x.fbx").write_text("")
    with pytest.raises(InputError, match="unsupported format"):
        hg.load_objects(tmp_path / "x.fbx")
    with pytest.raises(InputError, match="outside"):
        hg.MeshObject("bad", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 5]])


def test_instance_ids_are_stable_and_sequential():
    scene = hg.Scene()
    objs = [scene.add(hg.make_primitive("cube", name=f"c{i}", category_id=1)) for i in range(3)]
    assert [o.instance_id for o in objs] == [1, 2, 3]
    assert scene.by_name("c1").instance_id == 2
