"""Camera-pose sampling with proximity checks (our raster vs an Embree ray grid) and physics time, on the
tabletop of configs/tabletop_physics.yaml (20 real meshes from pybullet_data dropped on a table).

Run: .venv/bin/python tools/bench_sampling.py [--candidates 400] [--rounds 3] [--data PYBULLET_DATA] [--no-lenient]
Needs pybullet (+ pybullet_data), coacd and embreex (the ``bench`` / ``physics`` extras) and EGL.

Camera poses. One scene, one list of candidate poses drawn from the config's CameraSampler entry (shell
around the table, look-at the objects' point of interest), the config's checks (proximity min / avg /
no_background, min_coverage of the dropped objects). Both methods answer the same question per candidate
("which checks fail?") from the same pixel-centre grid (``check_width`` pixels wide):
  raster: hybridgen.sampling.camera_sampling.pose_failures - one low-resolution raster draw + readback;
  rays:   the grid's rays cast with trimesh's Embree intersector (embreex) against the posed scene mesh,
          distances and instance ids from the first hits, then the same ProximityChecks / coverage code.
A row for BlenderProc's default grid (10 x 10 rays, ``sqrt_number_of_rays``) is added for scale.
Setup (raster upload / BVH build) is timed apart; candidates/s are medians over rounds; "agree" is the
fraction of candidates both methods accept or reject alike (differences: rays at pixel centres that graze
edges, and the raster's near plane).

Physics. object.PhysicsPositioning's settings from the config, 20 objects from the same collision-free
start poses each round; wall time of simulate_physics (shapes built, simulated, poses written back), and
CoACD's decomposition of the two concave objects cold (empty cache) vs cached.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from harness import Stopwatch, Table

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "configs" / "tabletop_physics.yaml"


def _data_path(given: str | None) -> str:
    if given:
        return given
    try:
        import pybullet_data
    except ImportError:
        sys.exit("needs pybullet (pip install pybullet) or --data pointing at a pybullet_data folder")
    return pybullet_data.getDataPath()


def build(data: str) -> tuple[Any, dict[str, Any]]:
    """Run the config's modules up to (not including) the physics; return the context and the modules by
    name (the physics benchmark leaves the objects at rest, where the cameras then look)."""
    from hybridgen.config.config_file import load_config
    from hybridgen.run.context import RunContext
    from hybridgen.run.pipeline import build_modules

    config = load_config(CONFIG, [tempfile.mkdtemp(prefix="bench-sampling-"), data])
    modules = build_modules(config)
    context = RunContext(config=config)
    for module in modules:
        module.prepare(context)
    named = {module.module_name: module for module in modules}
    for module in modules:
        if module.module_name == "object.PhysicsPositioning":
            break
        module.run(context)
    return context, named


def bench_physics(context: Any, module: Any, rounds: int) -> list[dict[str, Any]]:
    from hybridgen.physics import simulate_physics
    from hybridgen.physics.shapes import convex_decomposition

    active = module.selected(context)
    passive = [o for o in context.scene.objects if all(o is not a for a in active)]
    start = {id(o): o.local2world.copy() for o in active}
    settings = module.settings(context)
    rows = []
    # decomposition of the concave objects: cold (empty cache) and cached
    concave = [o for o in active if o.attributes.get("collision_shape") == "convex_decomposition"]
    saved = os.environ.get("HYBRIDGEN_CACHE_DIR")
    with tempfile.TemporaryDirectory() as cache:
        os.environ["HYBRIDGEN_CACHE_DIR"] = cache
        for label in ("cold", "cached"):
            watch = Stopwatch()
            parts = sum(len(convex_decomposition(o.vertices, o.faces, settings.decomposition)) for o in concave)
            rows.append({"case": f"CoACD decomposition, {label}", "objects": len(concave), "parts": parts,
                         "wall": watch.read()[0]})
        # the simulation itself (decompositions cached, as on every run after the first)
        for substeps in (None, 1):
            walls, result = [], None
            for _ in range(rounds):
                for obj in active:
                    obj.local2world = start[id(obj)].copy()
                from dataclasses import replace

                result = simulate_physics(active, passive, replace(settings, substeps=substeps))
                walls.append(result.wall_seconds)
            assert result is not None
            rows.append({"case": "simulate_physics" + (" (auto substeps)" if substeps is None else
                                                       " (1 substep, thin objects may tunnel)"),
                         "objects": len(active), "simulated": result.simulated_time, "steps": result.steps,
                         "substeps": result.substeps, "at_rest": len(result.at_rest),
                         "wall": statistics.median(walls)})
    if saved is None:
        os.environ.pop("HYBRIDGEN_CACHE_DIR", None)
    else:
        os.environ["HYBRIDGEN_CACHE_DIR"] = saved
    return rows


class RayGrid:
    """The check grid's rays, cast with Embree against the posed scene mesh."""

    def __init__(self, scene: Any) -> None:
        import trimesh
        from trimesh.ray.ray_pyembree import RayMeshIntersector

        vertices, faces, owner, offset = [], [], [], 0
        for obj in scene.objects:
            vertices.append(obj.world_vertices())
            faces.append(obj.faces + offset)
            owner.append(np.full(len(obj.faces), obj.instance_id, dtype=np.int32))
            offset += len(obj.vertices)
        self.mesh = trimesh.Trimesh(np.concatenate(vertices), np.concatenate(faces), process=False)
        self.owner = np.concatenate(owner)
        self.intersector = RayMeshIntersector(self.mesh)
        self.intersector.intersects_first(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]))  # build the BVH now

    def cast(self, cam2world: np.ndarray, intr: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(distance (H,W), hit (H,W), instance ids (H,W)) of the pixel-centre rays."""
        directions = intr.pixel_rays().reshape(-1, 3)
        directions = directions / np.linalg.norm(directions, axis=1, keepdims=True)
        world = directions @ cam2world[:3, :3].T
        origins = np.broadcast_to(cam2world[:3, 3], world.shape)
        locations, rays, triangles = self.intersector.intersects_location(origins, world, multiple_hits=False)
        distance = np.full(len(world), np.inf, dtype=np.float32)
        instance = np.zeros(len(world), dtype=np.int32)
        distance[rays] = np.linalg.norm(locations - cam2world[:3, 3], axis=1)
        instance[rays] = self.owner[triangles]
        shape = (intr.height, intr.width)
        return distance.reshape(shape), (instance > 0).reshape(shape), instance.reshape(shape)


def ray_failures(grid: RayGrid, cam2world: np.ndarray, intr: Any, checks: Any) -> list[str]:
    """The checks ``pose_failures`` makes, answered from the ray grid (no hidden objects in this scene)."""
    distance, hit, instance = grid.cast(cam2world, intr)
    return checks.failures(cam2world, distance, hit, lambda: instance)


def bench_cameras(context: Any, module: Any, count: int, rounds: int) -> tuple[list[dict[str, Any]], dict]:
    from hybridgen.config.camera_poses import intrinsics_from_config, pose_from_entry
    from hybridgen.render.raster.raster_view import RasterView
    from hybridgen.sampling.camera_sampling import check_intrinsics, pose_failures
    from hybridgen.sampling.registry import DrawContext, draw

    cfg = module.config
    intr = intrinsics_from_config(cfg["intrinsics"])
    context.scene.camera.intrinsics = intr
    entry = cfg["cam_poses"][0]
    checks = module._checks(entry, context, "cam_poses[0]")  # the config's checks, ids resolved
    pose_part = {k: v for k, v in entry.items() if k in ("location", "rotation")}
    draw_ctx = DrawContext(np.random.default_rng(1234), context.scene)
    candidates = [pose_from_entry(draw(pose_part, draw_ctx)) for _ in range(count)]
    check = check_intrinsics(intr, cfg["check_width"])
    coarse = check_intrinsics(intr, 10)

    watch = Stopwatch()
    view = RasterView(context.scene)
    pose_failures(view, candidates[0], check, checks)  # first draw compiles / allocates
    raster_setup = watch.read()[0]
    watch = Stopwatch()
    grid = RayGrid(context.scene)
    ray_setup = watch.read()[0]

    def timed(fn: Any) -> tuple[float, list[bool]]:
        rates, accepted = [], []
        for _ in range(rounds):
            watch = Stopwatch()
            accepted = [not fn(pose) for pose in candidates]
            rates.append(len(candidates) / watch.read()[0])
        return statistics.median(rates), accepted

    raster_rate, raster_ok = timed(lambda pose: pose_failures(view, pose, check, checks))
    ray_rate, ray_ok = timed(lambda pose: ray_failures(grid, pose, check, checks))
    coarse_rate, coarse_ok = timed(lambda pose: ray_failures(grid, pose, coarse, checks))
    view.release()
    rows = []
    for name, grid_size, setup, rate, ok in (
            ("raster (ours, pose_failures)", check, raster_setup, raster_rate, raster_ok),
            ("Embree ray grid (trimesh)", check, ray_setup, ray_rate, ray_ok),
            ("Embree ray grid, BlenderProc 10x10", coarse, ray_setup, coarse_rate, coarse_ok)):
        agree = float(np.mean(np.array(ok) == np.array(raster_ok)))
        rows.append({"method": name, "grid": f"{grid_size.width}x{grid_size.height}", "setup": setup,
                     "rate": rate, "accepted": sum(ok), "accepted_rate": rate * sum(ok) / len(ok), "agree": agree})
    info = {"candidates": count, "triangles": context.scene.triangle_count, "objects": len(context.scene.objects),
            "image": f"{intr.width}x{intr.height}"}
    return rows, info


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--candidates", type=int, default=400, help="candidate camera poses per round")
    parser.add_argument("--rounds", type=int, default=3, help="timed rounds (medians are reported)")
    parser.add_argument("--data", help="pybullet_data folder (default: the installed one)")
    parser.add_argument("--lenient", action=argparse.BooleanOptionalAction, default=True,
                        help="load meshes whose MTL or texture files are missing, as `hybridgen run --lenient` does "
                        "(pybullet_data's lego.obj names a lego.mtl the wheel does not ship; default on); "
                        "--no-lenient stops on them")
    args = parser.parse_args()
    if args.lenient:
        from hybridgen.io.mesh_references import LENIENT_ENV

        os.environ[LENIENT_ENV] = "1"  # read by the mesh loader (a notice per such mesh instead of an error)
    data = _data_path(args.data)
    context, modules = build(data)
    physics_rows = bench_physics(context, modules["object.PhysicsPositioning"], args.rounds)
    camera_rows, info = bench_cameras(context, modules["camera.CameraSampler"], args.candidates, args.rounds)

    print(f"\nCamera poses with proximity checks: tabletop after physics, {info['objects']} objects, "
          f"{info['triangles']} triangles, image {info['image']}, {info['candidates']} candidates x {args.rounds} rounds")
    table = Table([("method", "<38"), ("grid", ">7"), ("setup s", ">8.3f"), ("cand/s", ">9.1f"), ("accepted", ">9"),
                   ("poses/s", ">8.1f"), ("vs raster", ">9.2f"), ("agree %", ">7.1f")])
    table.header()
    base = camera_rows[0]["rate"]
    for row in camera_rows:
        table.row(row["method"], row["grid"], row["setup"], row["rate"], f"{row['accepted']}/{info['candidates']}",
                  row["accepted_rate"], row["rate"] / base, row["agree"] * 100)
    print("\nPhysics (object.PhysicsPositioning settings of the config, same start poses each round)")
    table = Table([("case", "<52"), ("objects", ">7d"), ("sim s", ">6.2f"), ("steps", ">6d"), ("substeps", ">8d"),
                   ("at rest", ">7d"), ("wall s", ">7.2f"), ("x realtime", ">10.2f")])
    table.header()
    for row in physics_rows:
        if "simulated" in row:
            table.row(row["case"], row["objects"], row["simulated"], row["steps"], row["substeps"], row["at_rest"],
                      row["wall"], row["simulated"] / row["wall"])
        else:  # a decomposition: its convex parts in the "at rest" column
            table.row(row["case"], row["objects"], "", "", "", f"{row['parts']} pt", row["wall"], "")


if __name__ == "__main__":
    main()
