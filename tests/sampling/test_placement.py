"""Collision-free placement, verified with an independent surface intersection test (edges vs triangles)."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
import trimesh

import hybridgen as hg
from tests.conftest import REPO


def _world(obj: hg.MeshObject) -> trimesh.Trimesh:
    return trimesh.Trimesh(obj.world_vertices(), obj.faces, process=False)


def _edges_cross(a: trimesh.Trimesh, b: trimesh.Trimesh) -> bool:
    """Does any edge of ``a`` pass through a triangle of ``b``? (ray casting, independent of FCL)"""
    edges = a.edges_unique
    start, end = a.vertices[edges[:, 0]], a.vertices[edges[:, 1]]
    length = np.linalg.norm(end - start, axis=1)
    keep = length > 0
    direction = (end - start)[keep] / length[keep, None]
    hits, rays, _ = b.ray.intersects_location(start[keep], direction, multiple_hits=False)
    if len(rays) == 0:
        return False
    travelled = np.linalg.norm(hits - start[keep][rays], axis=1)
    return bool((travelled <= length[keep][rays]).any())


def _inside(a: trimesh.Trimesh, b: trimesh.Trimesh) -> bool:
    """Does a vertex of ``a`` lie inside ``b``, when ``b`` is closed? (trimesh's ray-parity test)"""
    solid = trimesh.Trimesh(b.vertices, b.faces)  # duplicate corners merged
    return bool(solid.is_watertight and solid.contains(a.vertices[:1]).any())


def surfaces_intersect(a: hg.MeshObject, b: hg.MeshObject) -> bool:
    """The surfaces cross, or one object lies entirely inside the other, closed, one."""
    ma, mb = _world(a), _world(b)
    return _edges_cross(ma, mb) or _edges_cross(mb, ma) or _inside(ma, mb) or _inside(mb, ma)


def _context(text: str, write_config):
    from hybridgen.config.config_file import load_config
    from hybridgen.run.context import RunContext
    from hybridgen.run.pipeline import build_modules

    config = load_config(write_config(text))
    context = RunContext(config=config)
    messages: list[str] = []
    context.log = messages.append
    modules = build_modules(config)
    for module in modules:
        module.prepare(context)
    for module in modules:
        module.run(context)
    return context, messages


BASE = """
modules:
  - name: main.Initializer
    config: {seed: %d}
  - name: loader.PrimitiveLoader
    config: {shape: cube, size: 1.0, name: table, category_id: 1, scale: [1.6, 1.0, 0.1], location: [0, 0, 0.7]}
""" + "".join(f"""
  - name: loader.PrimitiveLoader
    config: {{shape: {shape}, size: 0.25, name: item{i}, category_id: 2}}""" for i, shape in
              enumerate(["cube", "sphere", "cylinder", "cone", "torus", "cube"])) + f"""
  - name: loader.ObjLoader
    config: {{path: {REPO}/configs/assets/knot.obj, name: knot, category_id: 2, scale: 0.08}}
"""


def test_on_surface_sampler_rests_objects_without_collisions(write_config):
    text = BASE % 4 + """
  - name: object.OnSurfaceSampler
    config: {objects_to_sample: {category_id: 2}, surface: {name: table}, min_distance: 0.2, max_distance: 2.0,
             rot_sampler: {provider: sampler.UniformSO3, around_x: false, around_y: false}}
"""
    context, messages = _context(text, write_config)
    items = [o for o in context.scene.objects if o.category_id == 2]
    assert "placed 7 object(s)" in messages[-1]
    top = 0.75
    for obj in items:
        points = obj.world_vertices()
        assert points[:, 2].min() == pytest.approx(top, abs=2e-4)  # resting on the top face
        assert (np.abs(points[:, 0]) <= 0.8 + 1e-9).all() and (np.abs(points[:, 1]) <= 0.5 + 1e-9).all()
    for a, b in itertools.combinations(context.scene.objects, 2):
        assert not surfaces_intersect(a, b), (a.name, b.name)
    centres = np.array([o.local2world[:2, 3] for o in items])
    gaps = np.linalg.norm(centres[:, None] - centres[None], axis=-1) + np.eye(len(items)) * 9
    assert gaps.min() >= 0.2 - 1e-9


def test_object_pose_sampler_avoids_collisions_and_is_deterministic(write_config):
    text = BASE % 7 + """
  - name: object.ObjectPoseSampler
    config: {objects_to_sample: {category_id: 2},
             pos_sampler: {provider: sampler.Uniform3d, min: [-0.5, -0.4, 0.9], max: [0.5, 0.4, 1.5]},
             rot_sampler: {provider: sampler.UniformSO3}, max_iterations: 2000}
"""
    context, messages = _context(text, write_config)
    assert "placed 7 object(s)" in messages[-1]
    for a, b in itertools.combinations(context.scene.objects, 2):
        assert not surfaces_intersect(a, b), (a.name, b.name)
    again, _ = _context(text, write_config)
    for a, b in zip(context.scene.objects, again.scene.objects):
        np.testing.assert_array_equal(a.local2world, b.local2world)


def test_independent_check_detects_a_real_intersection():
    a = hg.make_primitive("cube", 1.0, name="a", category_id=1)
    b = hg.make_primitive("cube", 1.0, name="b", category_id=1, local2world=hg.object_pose([0.5, 0.3, 0.2]))
    c = hg.make_primitive("cube", 1.0, name="c", category_id=1, local2world=hg.object_pose([3, 0, 0]))
    assert surfaces_intersect(a, b) and not surfaces_intersect(a, c)
    from hybridgen.scene.collision import CollisionWorld

    world = CollisionWorld([a])
    assert world.collides(b) and not world.collides(c)


def test_an_object_inside_another_is_a_collision_both_ways():
    """Containment without touching surfaces: the independent check and the FCL world both see it."""
    from hybridgen.scene.collision import CollisionWorld

    big = hg.make_primitive("cube", 2.0, name="big", category_id=1, local2world=hg.object_pose([0, 0, 1], [0, 0, 0.3]))
    small = hg.make_primitive("sphere", 0.5, name="small", category_id=2, local2world=hg.object_pose([0.2, 0.1, 1]))
    outside = hg.make_primitive("sphere", 0.5, name="outside", category_id=2, local2world=hg.object_pose([3, 0, 1]))
    sheet = hg.make_primitive("plane", 4.0, name="sheet", category_id=3, local2world=hg.object_pose([0, 0, 0.5]))
    assert surfaces_intersect(small, big) and surfaces_intersect(big, small)
    assert not surfaces_intersect(outside, big)
    assert CollisionWorld([big]).collides(small) and CollisionWorld([small]).collides(big)
    assert not CollisionWorld([big]).collides(outside)
    # an open surface encloses nothing: a ball above (not touching) the sheet is free, one crossing it is not
    assert not CollisionWorld([sheet]).collides(small) and not surfaces_intersect(small, sheet)
    assert CollisionWorld([sheet]).collides(small, hg.object_pose([0, 0, 0.6]))


def test_collision_world_agrees_with_the_independent_check_under_scale_and_rotation():
    """Random poses of a torus near a non-uniformly scaled, rotated box and a scaled knot: the FCL world
    (scale baked into a BVH built once, rigid transforms after) gives the independent check's answer."""
    from hybridgen.scene import collision
    from hybridgen.scene.collision import CollisionWorld

    box = hg.make_primitive("cube", 1.0, name="box", category_id=1,
                            local2world=hg.object_pose([0, 0, 0], [0.3, -0.5, 0.8], [1.5, 0.4, 0.7]))
    knot = hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=2,
                           local2world=hg.object_pose([1.6, 0.2, 0.1], [0.2, 0.4, 0], 0.45))[0]
    ring = hg.make_primitive("torus", 0.8, name="ring", category_id=3)
    builds = []
    original_build = collision._Shape.build
    collision._Shape.build = classmethod(lambda cls, v, f: (builds.append(len(f)), original_build.__func__(cls, v, f))[1])
    try:
        world = CollisionWorld([box, knot])
        rng = np.random.default_rng(4)
        answers = []
        for _ in range(40):
            pose = hg.object_pose(rng.uniform([-1.2, -1.0, -0.8], [2.6, 1.0, 0.8]), rng.uniform(0, 6.3, 3),
                                  [1.3, 1.0, 0.6])
            ring.local2world = pose
            expected = surfaces_intersect(ring, box) or surfaces_intersect(ring, knot)
            answers.append(expected)
            assert world.collides(ring, pose) == expected, pose
    finally:
        collision._Shape.build = original_build
    assert 8 <= sum(answers) <= 32  # both outcomes are exercised
    assert len(builds) == 3  # one BVH per object (box, knot, ring), not one per test


def test_impossible_placement_is_a_clear_error(write_config, run_cli):
    text = BASE % 1 + """
  - name: object.ObjectPoseSampler
    config: {objects_to_sample: {category_id: 2}, max_iterations: 20,
             pos_sampler: {provider: sampler.Uniform3d, min: [0, 0, 0.7], max: [0, 0, 0.7]}}
"""
    code, _, err = run_cli("run", "-q", str(write_config(text)))
    assert code == 2 and "object.ObjectPoseSampler" in err and "no collision-free pose for" in err
