"""object.PhysicsPositioning / hybridgen.physics: objects end at rest on their supports, without
interpenetration (independent edge-vs-triangle test), deterministically; frames, decomposition, errors.

Measured with PyBullet 3.2.x at the default collision margin (1e-4 m): resting objects end 0.17 to 0.18 mm
above their support (Bullet keeps about 2 x margin between shapes) and no pair of objects intersects, so
the tests allow no penetration at all; "at rest" objects are within TOUCH of something they rest on.
"""
from __future__ import annotations

import itertools
import os
import re
import sys

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from hybridgen.physics import DecompositionSettings, PhysicsSettings, convex_decomposition, simulate_physics
from hybridgen.physics.bodies import split_linear
from tests.conftest import REPO
from tests.sampling.test_placement import _context, surfaces_intersect

TOUCH = 1e-3  # m: an object at rest is this close to another object or its support
MARGIN_GAP = (0.0, 5e-4)  # m: measured 0.16..0.19 mm between a resting object and a flat support

FAST_DECOMPOSITION = DecompositionSettings(threshold=0.1, max_convex_hull=8, mcts_iterations=20, mcts_nodes=10,
                                           resolution=500)


def u_shape(width: float = 0.3, height: float = 0.2, wall: float = 0.04, depth: float = 0.15) -> trimesh.Trimesh:
    """A closed, concave U (a cup without front and back walls), opening upwards, base at z = 0."""
    w, h, t = width, height, wall
    ring = np.array([(0, 0), (w, 0), (w, h), (w - t, h), (w - t, t), (t, t), (t, h), (0, h)], float) - [w / 2, 0]
    caps = np.array([(0, 1, 4), (0, 4, 5), (1, 2, 3), (1, 3, 4), (0, 5, 6), (0, 6, 7)])
    n = len(ring)
    vertices = np.vstack([np.column_stack([ring[:, 0], np.full(n, y), ring[:, 1]]) for y in (-depth / 2, depth / 2)])
    faces = [*caps, *(caps[:, ::-1] + n)]
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, j, j + n), (i, j + n, i + n)]
    mesh = trimesh.Trimesh(vertices, np.array(faces), process=False)
    trimesh.repair.fix_normals(mesh)
    assert mesh.is_watertight and mesh.volume > 0
    return mesh


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", str(tmp_path / "cache"))


def _pybullet_data() -> str:
    import pybullet_data

    return pybullet_data.getDataPath()


TABLETOP = """
modules:
  - name: main.Initializer
    config: {seed: 3}
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 4.0, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1.0, name: table, category_id: 2, scale: [0.8, 0.6, 0.05], location: [0, 0, 0.725]}
""" + "".join(f"""
  - name: loader.PrimitiveLoader
    config: {{shape: {shape}, size: 0.08, name: item{i}, category_id: 3, attributes: {{physics: true}}}}"""
              for i, shape in enumerate(["cube", "sphere", "cylinder", "cone", "torus"])) + """
  - name: loader.ObjLoader
    config: {path: %(repo)s/configs/assets/knot.obj, name: knot, category_id: 4, scale: 0.05,
             attributes: {physics: true}}
  - name: loader.ObjLoader
    config: {path: %(data)s/duck.obj, name: duck, category_id: 5, scale: 0.05, attributes: {physics: true}}
  - name: loader.ObjLoader
    config: {path: %(data)s/domino/domino.obj, name: domino, category_id: 6, scale: 1.5, attributes: {physics: true}}
  - name: object.ObjectPoseSampler
    config: {objects_to_sample: {physics: true}, rot_sampler: {provider: sampler.UniformSO3},
             pos_sampler: {provider: sampler.Uniform3d, min: [-0.3, -0.2, 0.85], max: [0.3, 0.2, 1.1]}}
  - name: object.PhysicsPositioning
    config: {min_simulation_time: 1.0, max_simulation_time: 6.0, check_object_interval: 0.25,
             object_stopped_location_threshold: 0.001, object_stopped_rotation_threshold: 0.01,
             rolling_friction: 0.01, spinning_friction: 0.001, on_not_at_rest: error}
"""


def test_dropped_objects_rest_on_the_table_without_interpenetration(write_config):
    text = TABLETOP % {"repo": REPO, "data": _pybullet_data()}
    context, messages = _context(text, write_config)
    summary = next(m for m in messages if m.startswith("object.PhysicsPositioning"))
    assert re.search(r"simulated \d+\.\d+ s, 8 objects at rest", summary), summary
    scene = context.scene
    active = [o for o in scene.objects if o.attributes.get("physics")]
    table_top = 0.75
    on_floor = 0
    for obj in active:  # lowest point: resting on the floor (fell off), or above the table top
        low = obj.world_vertices()[:, 2].min()
        if low < table_top:
            assert MARGIN_GAP[0] <= low <= MARGIN_GAP[1], (obj.name, low)
            on_floor += 1
        else:
            assert low - table_top >= MARGIN_GAP[0], (obj.name, low)
    assert on_floor <= 2
    for a, b in itertools.combinations(scene.objects, 2):
        assert not surfaces_intersect(a, b), (a.name, b.name)
    # at rest, not hovering: every object is within TOUCH of another object or the table
    manager = trimesh.collision.CollisionManager()
    for obj in scene.objects:
        manager.add_object(f"{obj.instance_id}", trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False))
    for obj in active:
        manager.remove_object(f"{obj.instance_id}")
        gap = manager.min_distance_single(trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False))
        manager.add_object(f"{obj.instance_id}", trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False))
        assert gap <= TOUCH, (obj.name, gap)
    # scale kept: the duck was loaded at 0.05, the domino at 1.5
    assert np.allclose(np.linalg.norm(scene.by_name("duck").local2world[:3, :3], axis=0), 0.05)
    assert np.allclose(np.linalg.norm(scene.by_name("domino").local2world[:3, :3], axis=0), 1.5)
    again, _ = _context(text, write_config)
    for a, b in zip(scene.objects, again.scene.objects):
        np.testing.assert_array_equal(a.local2world, b.local2world)


def test_a_resting_object_stays_put_whatever_its_origin_and_scale():
    """Body frame (centre of mass, principal axes) <-> object origin: an offset, rotated, non-uniformly
    scaled box already lying on the floor must keep its pose."""
    box = trimesh.creation.box([0.1, 0.06, 0.04])
    vertices = box.vertices + [0.35, -0.2, 0.02]  # origin far outside the mesh; bottom at local z = 0
    pose = hg.object_pose([0.1, 0.2, 0.0], [0, 0, 0.7], [1.5, 0.8, 1.2])
    lowest = (vertices @ pose[:3, :3].T)[:, 2].min()
    pose[2, 3] += 2e-4 - lowest
    obj = hg.MeshObject("box", vertices, box.faces, category_id=1, local2world=pose)
    floor = hg.make_primitive("plane", 4.0, name="floor", category_id=1)
    result = simulate_physics([obj], [floor], PhysicsSettings(min_time=0.5, max_time=2.0, check_interval=0.25,
                                                              position_threshold=1e-4, rotation_threshold=1e-3))
    assert result.at_rest == [obj] and result.simulated_time == pytest.approx(0.5)
    assert np.abs(obj.local2world[:3, 3] - pose[:3, 3]).max() < 3e-4
    np.testing.assert_allclose(obj.local2world[:3, :3], pose[:3, :3], atol=2e-3)
    np.testing.assert_allclose(np.linalg.norm(obj.local2world[:3, :3], axis=0), [1.5, 0.8, 1.2], rtol=1e-9)


def test_split_linear_keeps_scale_and_mirror():
    linear = hg.object_pose([0, 0, 0], [0.3, -0.2, 1.1], [2.0, 0.5, -1.5])[:3, :3]
    rotation, rest = split_linear(linear)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    np.testing.assert_allclose(rotation @ rest, linear, atol=1e-12)


def test_convex_decomposition_lets_an_object_into_a_cavity_and_is_cached(tmp_path):
    cup_mesh = u_shape()
    rim = 0.2

    def drop(shape: str) -> float:
        floor = hg.make_primitive("plane", 2.0, name="floor", category_id=1)
        cup = hg.MeshObject("cup", cup_mesh.vertices, cup_mesh.faces, category_id=2,
                            local2world=hg.object_pose([0, 0, 0.01]), attributes={"collision_shape": shape})
        cube = hg.make_primitive("cube", 0.06, name="cube", category_id=3, local2world=hg.object_pose([0, 0, 0.3]))
        settings = PhysicsSettings(min_time=1.0, max_time=4.0, decomposition=FAST_DECOMPOSITION)
        result = simulate_physics([cup, cube], [floor], settings)
        assert len(result.at_rest) == 2
        assert not surfaces_intersect(cup, cube)
        return float(cube.world_vertices()[:, 2].min() - cup.world_vertices()[:, 2].min())

    assert drop("convex_hull") >= rim  # the hull closes the cavity: the cube stays on top
    assert drop("convex_decomposition") < 0.05  # parts follow the U: the cube drops onto its base (0.04)
    cached = list((tmp_path / "cache" / "coacd").glob("*.npz"))
    assert len(cached) == 1
    import coacd

    def fail(*args, **kwargs):
        raise AssertionError("decomposition was recomputed instead of read from the cache")

    original = coacd.run_coacd
    coacd.run_coacd = fail
    try:
        parts = convex_decomposition(cup_mesh.vertices, cup_mesh.faces, FAST_DECOMPOSITION)
    finally:
        coacd.run_coacd = original
    assert 2 <= len(parts) <= 8
    for vertices, faces in parts:  # every part is convex: it equals its hull
        part = trimesh.Trimesh(vertices, faces)
        assert part.convex_hull.volume == pytest.approx(part.volume, rel=1e-6)


def test_convex_decomposition_caches_nothing_when_the_cache_is_off(tmp_path, monkeypatch):
    monkeypatch.setenv("HYBRIDGEN_CACHE_DIR", "off")
    monkeypatch.chdir(tmp_path)  # "off" once named a folder in the working directory
    cup_mesh = u_shape()
    parts = convex_decomposition(cup_mesh.vertices, cup_mesh.faces, FAST_DECOMPOSITION)
    assert 2 <= len(parts) <= 8
    assert list(tmp_path.rglob("*")) == []


def test_physics_errors_name_the_module(write_config, run_cli):
    base = """
modules:
  - name: loader.PrimitiveLoader
    config: {shape: plane, size: 4.0, name: floor, category_id: 1}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 0.2, name: box, category_id: 2, location: [0, 0, 0.5], attributes: {physics: %s}}
  - name: object.PhysicsPositioning
    config: {%s}
"""

    def error(physics: str, config: str) -> str:
        code, _, err = run_cli("run", "-q", str(write_config(base % (physics, config))))
        assert code == 2 and "module 'object.PhysicsPositioning'" in err, err
        return err

    assert "active_objects matches no object" in error("false", "max_simulation_time: 1.0")
    err = error("false", "active_objects: {name: floor}, passive_objects: {name: box}")
    assert "active object 'floor'" in err and "flat" in err
    assert "unknown decomposition parameter(s) ['treshold']" in error("true", "decomposition: {treshold: 0.1}")
    err = error("true", "min_simulation_time: 0.1, max_simulation_time: 0.2, on_not_at_rest: error")
    assert "not at rest after 0.20 s: 'box'" in err
    err = error("true", "min_simulation_time: 2.0, max_simulation_time: 1.0")
    assert "key 'min_simulation_time'" in err and "2.0 s > max_simulation_time 1.0 s" in err


def test_missing_pybullet_is_an_actionable_error(monkeypatch):
    from hybridgen.errors import SystemSetupError

    monkeypatch.setitem(sys.modules, "pybullet", None)
    floor = hg.make_primitive("plane", 4.0, name="floor", category_id=1)
    box = hg.make_primitive("cube", 0.2, name="box", category_id=1, local2world=hg.object_pose([0, 0, 1]))
    with pytest.raises(SystemSetupError, match=r"pip install pybullet"):
        simulate_physics([box], [floor], PhysicsSettings(min_time=0.1, max_time=0.2))
    assert os.environ["HYBRIDGEN_CACHE_DIR"]  # the fixture kept the user's cache untouched
