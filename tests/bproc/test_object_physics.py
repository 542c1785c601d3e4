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


def test_unsupported_shapes_raise_one_line(bproc) -> None:  # noqa: F811
    from hybridgen.errors import InputError

    ground = bproc.object.create_primitive("PLANE", size=10.0)
    ground.enable_rigidbody(False, collision_shape="MESH")
    ball = bproc.object.create_primitive("SPHERE", location=[0, 0, 2])
    ball.enable_rigidbody(True, collision_shape="SPHERE")
    with pytest.raises(InputError, match="collision_shape='SPHERE'.*not supported"):
        bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=1, max_simulation_time=2)
