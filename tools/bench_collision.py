"""Collision tests per second: hybridgen's CollisionWorld (BVH built once per object, rigid transforms after)
against rebuilding the posed mesh's BVH for every test (trimesh's CollisionManager, what placement did
before). Same poses, same answers; the ratio is what counts on a shared machine.

Run: .venv/bin/python tools/bench_collision.py [--subdivisions 6] [--tests 60]
"""
from __future__ import annotations

import argparse

import numpy as np
import trimesh
from harness import Stopwatch

import hybridgen as hg
from hybridgen.scene.collision import CollisionWorld


def rebuild_per_test(obstacle: hg.MeshObject, obj: hg.MeshObject, pose: np.ndarray) -> bool:
    manager = trimesh.collision.CollisionManager()
    manager.add_object("o", trimesh.Trimesh(obstacle.world_vertices(), obstacle.faces, process=False))
    posed = trimesh.Trimesh(obj.vertices @ pose[:3, :3].T + pose[:3, 3], obj.faces, process=False)
    return bool(manager.in_collision_single(posed))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subdivisions", type=int, default=6, help="icosphere subdivisions (6: 81,920 triangles)")
    parser.add_argument("--tests", type=int, default=60)
    args = parser.parse_args()
    sphere = trimesh.creation.icosphere(subdivisions=args.subdivisions)
    obj = hg.MeshObject("mesh", sphere.vertices * 0.3, sphere.faces, category_id=1)
    obstacle = hg.make_primitive("cube", 0.5, name="obstacle", category_id=2, local2world=hg.object_pose([0.7, 0, 0]))
    rng = np.random.default_rng(0)
    poses = [hg.object_pose(rng.uniform(-1, 1, 3), rng.uniform(0, 6.3, 3), [1.0, 1.2, 0.8]) for _ in range(args.tests)]
    world = CollisionWorld([obstacle])
    watch = Stopwatch()
    world.collides(obj, poses[0])
    first = watch.read()[0]
    times, ours = [], []
    for pose in poses:
        watch = Stopwatch()
        ours.append(world.collides(obj, pose))
        times.append(watch.read()[0])
    baseline_times, theirs = [], []
    for pose in poses[: max(3, args.tests // 10)]:
        watch = Stopwatch()
        theirs.append(rebuild_per_test(obstacle, obj, pose))
        baseline_times.append(watch.read()[0])
    assert ours[:len(theirs)] == theirs, "different answers"
    ours_ms, theirs_ms = np.median(times) * 1e3, np.median(baseline_times) * 1e3
    print(f"{len(obj.faces)} triangles, {sum(ours)}/{len(ours)} poses collide")
    print(f"CollisionWorld: first test (builds the BVH) {first * 1e3:.1f} ms, then median {ours_ms:.2f} ms per test")
    print(f"rebuild per test: median {theirs_ms:.1f} ms per test; ratio {theirs_ms / ours_ms:.0f}x")


if __name__ == "__main__":
    main()
