"""Ray casts and BVH trees of bproc.object / bproc.types.MeshObject against analytic hits, the mathutils stand-in's
rotations against hand-computed matrices, merge_objects and bproc.lighting.light_surface."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture


def test_ray_casts_hit_where_the_geometry_is(bproc) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE", size=1.0, location=[0, 0, 2], scale=[1, 1, 2])  # z 1..3
    # Blender bakes the operator's scale into the mesh: in the local frame the top face is at z 1 (bpy 4.2:
    # ray_cast((0, 0, 3), (0, 0, -1)) hits (0, 0, 1), within distance 2.1 but not 1.9)
    assert np.allclose(cube.get_scale(), 1.0)
    hit, location, normal, _ = cube.ray_cast([0, 0, 5], [0, 0, -3])
    assert hit and np.allclose(location, [0, 0, 1.0]) and np.allclose(normal, [0, 0, 1])
    assert cube.ray_cast([0, 0, 5], [0, 0, -1], max_distance=4.1)[0] is True  # 4 m to the local top face
    assert cube.ray_cast([0, 0, 5], [0, 0, -1], max_distance=3.9)[0] is False
    tree = bproc.object.create_bvh_tree_multi_objects([cube])
    location, normal, _, distance = tree.ray_cast([0.1, 0.2, 10], [0, 0, -1])
    assert np.allclose(np.array(location), [0.1, 0.2, 3.0]) and distance == pytest.approx(7.0)
    assert tree.ray_cast([0.1, 0.2, 10], [0, 0, -1], 6.9) == (None, None, None, None)
    cube.set_location([5, 0, 0])  # a tree keeps the geometry it was built from
    assert tree.ray_cast([0.1, 0.2, 10], [0, 0, -1])[3] == pytest.approx(7.0)


def test_scene_ray_cast_names_the_first_object(bproc) -> None:  # noqa: F811
    low = bproc.object.create_primitive("PLANE", size=4.0)
    high = bproc.object.create_primitive("CUBE", size=1.0, location=[1, 0, 1])
    hit, location, normal, _, obj, matrix = bproc.object.scene_ray_cast([1, 0, 5], [0, 0, -1])
    assert hit and obj is high and np.allclose(location, [1, 0, 1.5]) and np.allclose(matrix, high.get_local2world_mat())
    assert bproc.object.scene_ray_cast([-1, 0, 5], [0, 0, -1])[4] is low
    assert bproc.object.scene_ray_cast([9, 0, 5], [0, 0, -1])[0] is False
    assert high.position_is_above_object([1, 0, 5]) and not low.position_is_above_object([1, 0, 5])
    assert low.position_is_above_object([1, 0, 5], check_no_objects_in_between=False)


def test_mathutils_rotations() -> None:
    from hybridgen.bproc import mathutils_standin as mathutils

    quarter = np.array(mathutils.Matrix.Rotation(np.pi / 2, 3, "Z"))
    assert np.allclose(quarter @ [1, 0, 0], [0, 1, 0])  # counter-clockwise about +Z
    axis = np.array([1.0, 1.0, 1.0]) / np.sqrt(3)
    third = np.array(mathutils.Matrix.Rotation(2 * np.pi / 3, 3, axis))
    assert np.allclose(third @ [1, 0, 0], [0, 1, 0])  # a third turn about the diagonal cycles the axes
    assert np.array(mathutils.Matrix.Rotation(0.3, 4, "X")).shape == (4, 4)
    one = np.array(mathutils.Matrix.Rotation(np.array([np.pi / 2]), 3, [0, 0, 2]))  # a random walk's 1-array angle
    assert np.allclose(one, quarter)
    euler = mathutils.Euler((0.1, 0.2, 0.3))
    rz, ry, rx = (np.array(mathutils.Matrix.Rotation(a, 3, k)) for a, k in ((0.3, "Z"), (0.2, "Y"), (0.1, "X")))
    assert np.allclose(np.array(euler.to_matrix()), rz @ ry @ rx)  # Blender's XYZ order
    euler.rotate(mathutils.Euler((0, 0, 0.5)))
    assert np.allclose(np.array(euler.to_matrix()), np.array(mathutils.Matrix.Rotation(0.8, 3, "Z")) @ ry @ rx)
    quaternion = mathutils.Quaternion((np.cos(0.25), 0, 0, np.sin(0.25)))  # 0.5 rad about z
    assert np.allclose(np.array(quaternion.to_matrix()), np.array(mathutils.Matrix.Rotation(0.5, 3, "Z")))
    with pytest.raises(Exception, match="mathutils.noise is not supported"):
        mathutils.noise  # noqa: B018


def test_merge_objects_parents_only_the_free_objects(bproc) -> None:  # noqa: F811
    a = bproc.object.create_primitive("CUBE", location=[1, 0, 0])
    b = bproc.object.create_primitive("CUBE", location=[0, 2, 0])
    b.set_parent(a)
    parent = bproc.object.merge_objects([a, b], "group")
    assert parent.get_name() == "group" and a.get_parent() is parent and b.get_parent() is a
    assert np.allclose(b.get_local2world_mat()[:3, 3], [0, 2, 0])


def test_light_surface_makes_materials_emissive(bproc) -> None:  # noqa: F811
    lamp = bproc.object.create_primitive("PLANE")
    bare = bproc.object.create_primitive("PLANE")
    shared = bproc.material.create("shade")
    lamp.add_material(shared)
    other = bproc.object.create_primitive("CUBE")
    other.add_material(shared)
    bproc.lighting.light_surface([lamp, bare], emission_strength=5.0, emission_color=[1, 0.5, 0.25, 1])
    copy = lamp.get_materials()[0]
    assert copy is not shared and copy.get_name() == "shade.001_emission" and copy.get_cp("is_lamp")
    assert other.get_materials()[0] is shared and shared.blender_obj.emission_strength == 0
    assert copy.blender_obj.emission_strength == 5.0 and copy.blender_obj.emission == (1.0, 0.5, 0.25)
    assert bare.get_materials()[0].get_name() == "TextureLess_emission"


def test_compute_poi_takes_a_list_or_an_object_array(bproc) -> None:  # noqa: F811
    cubes = [bproc.object.create_primitive("CUBE", location=[x, 0.0, 0.5]) for x in (0.0, 1.0, 5.0)]
    # box centres at x = 0, 1, 5; their mean x = 2: the closest centre is the cube at x = 1
    np.testing.assert_allclose(bproc.object.compute_poi(cubes), [1.0, 0.0, 0.5])
    picked = np.random.default_rng(0).choice(cubes, size=10)  # what BOP examples pass
    np.testing.assert_allclose(bproc.object.compute_poi(np.array(cubes, dtype=object)), [1.0, 0.0, 0.5])
    assert bproc.object.compute_poi(picked).shape == (3,)
    with pytest.raises(Exception, match="at least one object"):
        bproc.object.compute_poi(np.array([], dtype=object))
