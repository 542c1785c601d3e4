"""bproc.object physics: rigid-body settings as BlenderProc sets them, resting heights after
simulate_physics_and_fix_final_poses, and simulate_physics' keyed animation and origin shifts."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture

pytest.importorskip("pybullet")


def test_enable_rigidbody_mass_from_bound_box(bproc) -> None:  # noqa: F811
    box = bproc.object.create_primitive("CUBE", size=0.5, scale=[2, 1, 1])
    box.enable_rigidbody(True, mass_factor=3.0, friction=0.8)
    body = box.get_rigidbody()
    assert body.type == "ACTIVE" and body.collision_shape == "CONVEX_HULL"
    assert body.mass == pytest.approx(1.0 * 0.5 * 0.5 * 3.0)  # bound box volume (m^3) x mass_factor
    assert body.friction == 0.8 and body.collision_margin == 0.001
    box.disable_rigidbody()
    assert not box.has_rigidbody_enabled()


def test_cube_comes_to_rest_on_a_plane(bproc) -> None:  # noqa: F811
    ground = bproc.object.create_primitive("PLANE", size=10.0)
    ground.enable_rigidbody(False, collision_shape="BOX")  # a flat box: its triangles
    cube = bproc.object.create_primitive("CUBE", size=0.4, location=[0.3, -0.2, 1.0], scale=[1, 1, 0.5])
    cube.enable_rigidbody(True)
    bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=1, max_simulation_time=4,
                                                      check_object_interval=1)
    # half height 0.1 m, plus Bullet's margin on both bodies (0.001 m each)
    assert cube.get_location()[2] == pytest.approx(0.1 + 0.002, abs=1e-3)
    assert np.allclose(cube.get_location()[:2], [0.3, -0.2], atol=0.03)  # Bullet's contact jitter on landing
    assert np.allclose(cube.get_scale(), [1, 1, 1])  # Blender bakes the operator's scale into the mesh
    assert np.allclose(cube.get_rotation_mat()[:, 2], [0, 0, 1], atol=1e-3)  # still flat on its face
    assert np.allclose(ground.get_location(), 0)


def test_simulate_physics_keys_the_fall(bproc) -> None:  # noqa: F811
    ground = bproc.object.create_primitive("PLANE", size=10.0)
    ground.enable_rigidbody(False, collision_shape="MESH")
    cube = bproc.object.create_primitive("CUBE", size=0.4, location=[0, 0, 3.0])
    cube.enable_rigidbody(True, linear_damping=0.0)
    shifts = bproc.object.simulate_physics(min_simulation_time=1, max_simulation_time=3, check_object_interval=1)
    assert set(shifts) == {"Plane", "Cube"} and np.allclose(shifts["Cube"], 0, atol=1e-9)
    assert np.allclose(cube.get_location(1), [0, 0, 3.0])  # frame 1: the start
    t = 12 / 24  # frame 13: half a second of free fall
    assert cube.get_location(13)[2] == pytest.approx(3.0 - 0.5 * 9.81 * t * t, abs=0.02)
    assert cube.get_location(60)[2] == pytest.approx(0.2 + 0.002, abs=1e-3)


def test_compound_without_its_decomposition_raises_one_line(bproc) -> None:  # noqa: F811
    from hybridgen.errors import InputError

    ground = bproc.object.create_primitive("PLANE", size=10.0)
    ground.enable_rigidbody(False, collision_shape="MESH")
    ball = bproc.object.create_primitive("SPHERE", location=[0, 0, 2])
    ball.enable_rigidbody(True, collision_shape="COMPOUND")
    with pytest.raises(InputError, match="collision_shape='COMPOUND'.*build_convex_decomposition_collision_shape"):
        bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=1, max_simulation_time=2)


@pytest.mark.parametrize("shape, dims, rest", [("SPHERE", (0.4, 1.2, 0.6), 0.6), ("CAPSULE", (0.4, 1.2, 0.6), 0.6),
                                               ("CYLINDER", (0.4, 0.6, 1.0), 0.5), ("CONE", (0.4, 0.6, 1.0), 0.5)])
def test_primitive_shapes_rest_as_blenders(bproc, shape: str, dims: tuple, rest: float) -> None:  # noqa: F811
    """Blender's primitive shapes from the object's dimensions (hybridgen/bproc/physics.py PRIMITIVE_SHAPES; measured
    with BlenderProc on bpy 4.2 with boxes whose origin was their bottom face: 0.3 m above the ground for the sphere
    and the squat capsule, on it for the others): a box centred on its origin rests with it at the sphere's radius,
    max(dims) / 2, or at half its height (the capsule of a squat box is that sphere; balls may roll)."""
    ground = bproc.object.create_primitive("PLANE", size=10.0)
    ground.enable_rigidbody(False, collision_shape="MESH")
    box = bproc.object.create_primitive("CUBE", scale=[d / 2 for d in dims], location=[0, 0, 1.5])
    box.persist_transformation_into_mesh(location=False, rotation=False, scale=True)
    box.enable_rigidbody(True, collision_shape=shape, collision_margin=0.0)
    bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=2, max_simulation_time=4,
                                                      check_object_interval=1)
    assert box.get_location()[2] == pytest.approx(rest, abs=0.02)
    if shape in ("CYLINDER", "CONE"):
        assert np.abs(box.get_rotation_euler()[:2]).max() < 0.05  # still upright


def test_a_tall_capsule_spans_the_box_height() -> None:
    """A 0.4 x 0.6 x 1 m box's capsule: radius 0.3 (half the larger horizontal side), 1 m tall caps included (a
    capsule standing on its cap is balanced on a point: its resting pose is not a test of the shape)."""
    from hybridgen.bproc.physics import primitive_hull
    from hybridgen.scene.mesh_object import MeshObject

    corners = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (-0.3, 0.3) for z in (0.0, 1.0)])
    box = MeshObject("box", corners, np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                                               [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]))
    low, high = primitive_hull("CAPSULE", box).bounds
    np.testing.assert_allclose(low, [-0.3, -0.3, 0.0], atol=0.01)
    np.testing.assert_allclose(high, [0.3, 0.3, 1.0], atol=0.01)
    low, high = primitive_hull("SPHERE", box).bounds  # radius max(dims) / 2 around the surface centroid
    np.testing.assert_allclose(low, [-0.5, -0.5, 0.0], atol=0.01)
    plane = MeshObject("plane", corners[::2], np.array([[0, 1, 3], [0, 3, 2]]))  # flat: z = 0
    disk = primitive_hull("CYLINDER", plane)  # a thin disk, not a degenerate hull
    assert disk.is_watertight and disk.extents[2] == pytest.approx(1e-4) and disk.extents[1] == pytest.approx(0.6)