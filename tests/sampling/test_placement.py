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


def surfaces_intersect(a: hg.MeshObject, b: hg.MeshObject) -> bool:
    ma, mb = _world(a), _world(b)
    return _edges_cross(ma, mb) or _edges_cross(mb, ma)


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


def test_impossible_placement_is_a_clear_error(write_config, run_cli):
    text = BASE % 1 + """
  - name: object.ObjectPoseSampler
    config: {objects_to_sample: {category_id: 2}, max_iterations: 20,
             pos_sampler: {provider: sampler.Uniform3d, min: [0, 0, 0.7], max: [0, 0, 0.7]}}
"""
    code, _, err = run_cli("run", "-q", str(write_config(text)))
    assert code == 2 and "object.ObjectPoseSampler" in err and "no collision-free pose for" in err
