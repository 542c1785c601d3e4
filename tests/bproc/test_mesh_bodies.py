"""Active rigid bodies with collision_shape MESH (Blender's GImpact: every triangle collides): a cube comes to rest
on a passive floor, and an open tube - solidified as shapenet_with_scenenet solidifies its object - falls around a
post it would rest on as a convex hull; the GImpact mass properties (surface centroid, vertex point masses)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture

pytest.importorskip("pybullet")

SIDES = 16


def _tube(path: Path, radius: float = 0.3, height: float = 0.2) -> Path:
    """An OBJ of an open tube (no caps) around the z axis, z in 0..height, quads."""
    ring = [(radius * np.cos(2 * np.pi * i / SIDES), radius * np.sin(2 * np.pi * i / SIDES)) for i in range(SIDES)]
    lines = ["o Tube"] + [f"v {x} {z} {-y}" for z in (0.0, height) for x, y in ring]  # OBJ is Y up
    lines += [f"f {i + 1} {(i + 1) % SIDES + 1} {SIDES + (i + 1) % SIDES + 1} {SIDES + i + 1}" for i in range(SIDES)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _floor_and_post(bproc) -> None:  # noqa: F811
    floor = bproc.object.create_primitive("PLANE", size=10.0)
    floor.enable_rigidbody(False, collision_shape="MESH")
    post = bproc.object.create_primitive("CUBE", size=1.0, location=[0, 0, 0.5], scale=[0.1, 0.1, 1.0])  # top z = 1
    post.enable_rigidbody(False, collision_shape="MESH")


def test_an_active_mesh_cube_rests_on_the_floor(bproc) -> None:  # noqa: F811
    floor = bproc.object.create_primitive("PLANE", size=10.0)
    floor.enable_rigidbody(False, collision_shape="MESH")
    cube = bproc.object.create_primitive("CUBE", size=0.4, location=[0.2, 0.1, 0.8], rotation=[0.0, 0.0, 0.4])
    cube.enable_rigidbody(True, collision_shape="MESH")
    bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=1, max_simulation_time=4,
                                                      check_object_interval=0.5)
    lowest = cube.world_triangles()[0][:, 2].min()
    assert lowest == pytest.approx(0.002, abs=2e-4)  # resting on it: the two margins of 1 mm apart
    assert np.allclose(cube.get_rotation_mat()[:, 2], [0, 0, 1], atol=2e-3)
    assert cube.get_location()[2] == pytest.approx(0.2 + 0.002, abs=1e-3)


@pytest.mark.parametrize("shape, lowest", [("MESH", 0.0), ("CONVEX_HULL", 1.0)])
def test_a_solidified_tube_falls_around_a_post_only_as_a_mesh(bproc, tmp_path: Path, shape: str,  # noqa: F811
                                                            lowest: float) -> None:
    _floor_and_post(bproc)
    tube, = bproc.loader.load_obj(str(_tube(tmp_path / "tube.obj")))
    tube.set_location([0.0, 0.0, 1.3])
    tube.add_modifier("SOLIDIFY", thickness=0.02)
    tube.enable_rigidbody(True, mass_factor=2000, collision_margin=0.0001, collision_shape=shape)
    bproc.object.simulate_physics_and_fix_final_poses(min_simulation_time=1, max_simulation_time=4,
                                                      check_object_interval=0.5)
    vertices = tube.world_triangles()[0]  # on the floor / on the post's top, the margins (1 mm + 0.1 mm) apart
    assert vertices[:, 2].min() == pytest.approx(lowest + 1.1e-3, abs=3e-4)
    assert np.hypot(*tube.get_location()[:2]) < 0.25  # still around the post


def test_gimpact_mass_properties() -> None:
    from hybridgen.physics.mesh_body import triangle_geometry

    corners = np.array([(x, y, z) for x in (0, 2) for y in (0, 1) for z in (0, 1)], float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                      [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])  # a 2 x 1 x 1 box
    geometry = triangle_geometry(corners, faces)
    assert geometry.kind == "triangles" and len(geometry.parts) == 12
    assert np.allclose(geometry.center_mass, [1.0, 0.5, 0.5])  # the surface centroid
    assert geometry.volume == pytest.approx(2.0)  # closed: its own volume
    per_unit_mass = geometry.inertia / geometry.volume  # 8 point masses of 1/8 at (+-1, +-0.5, +-0.5)
    assert np.allclose(per_unit_mass, np.diag([0.5, 1.25, 1.25]))
    scaled = triangle_geometry(corners, faces, np.diag([1.0, 1.0, 3.0]))
    assert np.allclose(scaled.center_mass, [1.0, 0.5, 1.5]) and scaled.volume == pytest.approx(6.0)
