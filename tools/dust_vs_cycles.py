"""hybridgen's dust films (``bproc.material.add_dust``) against the real BlenderProc's in Blender 4.2's Cycles.

    .venv/bin/python tools/dust_vs_cycles.py [--res 160x120] [--spp 256] [--store tests/render/data/dust_cycles.json]

The scene (both engines, same triangles, UVs and normals): four 0.9 m squares in front - dust strength 0, 0.5
and 1 facing up and one of strength 1 wound facing down, seen from above - and three UV spheres (r 0.42 m) of
strength 0, 0.5, 1 behind them, all over a blue Principled base (roughness 0.5, Specular IOR Level 0.5), texture
scale 0.1 (0.05 on the flipped square, the dust example's), under a sun 55 degrees high and a dim sky. Cycles
runs through tools/dust_cycles_scene.py in ``.venv-blenderproc`` with BlenderProc's own ``add_dust``.

Printed, per object: (1) the mean linear radiance hybridgen / Cycles per channel (both converged estimates at
``--spp``, equal bounces, no clamp, no denoising; pixels well inside each object, from an analytic ray cast),
and hybridgen's raster albedo and its diffuse-color pass over Cycles' DiffCol pass (the albedo is the base color,
Cycles' diffuse color and hybridgen's ``diffuse_color`` what the specular layer leaves of it; pixel centres against
pixel areas of a sub-pixel pattern add about 1.5 %); (2) the dust weight w: Cycles' exact w at one sample per pixel (its BSDFs replaced by black and white emission)
against hybridgen's at the same points (rays from the camera to Cycles' Position pass, the dust BSDF's
``eval_diffuse_reflectance`` with a black base and a white dust color) - mean w and the share of "dusty" points
(w >= 0.6 x strength: the flakes) on up-facing (normal z > 0.8) and side-facing (|z| < 0.35) parts, and the
largest pointwise difference. ``--store`` writes a sample of Cycles' points (UV, normal, view direction, w) as the
table tests/render/test_dust.py checks hybridgen's weight against.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tools"))
BASE = {"base_color": (0.1, 0.25, 0.6), "roughness": 0.5, "specular": 0.5}
PLANES = [("plane_s0", -1.65, 0.0, 0.1, 1.0), ("plane_s05", -0.55, 0.5, 0.1, 1.0), ("plane_s1", 0.55, 1.0, 0.1, 1.0),
          ("flipped_s1", 1.65, 1.0, 0.05, -1.0)]  # name, x, strength, texture scale, normal z
SPHERES = [("ball_s0", -1.2, 0.0), ("ball_s05", 0.0, 0.5), ("ball_s1", 1.2, 1.0)]
PLANE_Y, HALF, SPHERE_Y, RADIUS = -0.9, 0.45, 0.8, 0.42
CAMERA = ([0.0, -4.2, 3.0], [0.0, 0.2, 0.2], 0.95)  # location, target, horizontal fov (rad)
SUN = (math.radians(35.0), math.radians(20.0), 2.5)  # Euler x, z (rad), W/m^2
WORLD = (0.05, 0.06, 0.08)


def plane(x: float, normal_z: float) -> dict[str, np.ndarray]:
    """A square at height 0, UV 0..1 over it, wound so its normal is +z or -z."""
    corners = np.array([[-HALF, -HALF, 0], [HALF, -HALF, 0], [HALF, HALF, 0], [-HALF, HALF, 0]]) + [x, PLANE_Y, 0]
    faces = np.array([[0, 1, 2], [0, 2, 3]]) if normal_z > 0 else np.array([[0, 2, 1], [0, 3, 2]])
    return {"vertices": corners, "faces": faces, "uvs": np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]),
            "normals": np.tile([0.0, 0.0, normal_z], (4, 1))}


def sphere(x: float, segments: int = 64, rings: int = 32) -> dict[str, np.ndarray]:
    """A UV sphere (seam and pole vertices repeated per UV), u around z, v from the bottom pole up."""
    u, v = np.meshgrid(np.linspace(0, 1, segments + 1), np.linspace(0, 1, rings + 1))
    phi, theta = 2 * np.pi * u, np.pi * (1 - v)
    normals = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1).reshape(-1, 3)
    index = np.arange((rings + 1) * (segments + 1)).reshape(rings + 1, segments + 1)
    a, b, c, d = index[:-1, :-1], index[:-1, 1:], index[1:, 1:], index[1:, :-1]
    faces = np.concatenate([np.stack([a, b, c], -1)[1:].reshape(-1, 3), np.stack([a, c, d], -1)[:-1].reshape(-1, 3)])
    return {"vertices": normals * RADIUS + [x, SPHERE_Y, RADIUS + 0.03], "faces": faces,
            "uvs": np.stack([u.ravel(), v.ravel()], -1), "normals": normals}


def layout() -> list[dict[str, Any]]:
    """Every object: name, mesh arrays, dust layers [(strength, texture scale)]."""
    objects = [{"name": n, "dust": [(s, t)], **plane(x, z)} for n, x, s, t, z in PLANES]
    return objects + [{"name": n, "dust": [(s, 0.1)], **sphere(x)} for n, x, s in SPHERES]


def hybridgen_scene(objects: list[dict[str, Any]], size: tuple[int, int], weight_mode: bool) -> Any:
    """The scene in hybridgen; ``weight_mode``: black bases, white dust, no lights (w by reflectance)."""
    import hybridgen as hg
    from hybridgen.scene.dust import Dust

    scene = hg.Scene()
    for entry in objects:
        material = hg.Material(name=entry["name"], base_color=(*BASE["base_color"], 1.0), roughness=BASE["roughness"],
                               specular=BASE["specular"])
        material.dust = tuple(Dust(s, t) for s, t in entry["dust"])
        if weight_mode:
            material.base_color, material.specular = (0.0, 0.0, 0.0, 1.0), 0.0
            material.dust = tuple(Dust(s, t, color=(1.0, 1.0, 1.0)) for s, t in entry["dust"])
        scene.add(hg.MeshObject(name=entry["name"], vertices=entry["vertices"], faces=entry["faces"],
                                uvs=entry["uvs"], vertex_normals=entry["normals"], material=material))
    scene.world.color, scene.world.strength = WORLD, 1.0
    scene.add_light(hg.Light("sun", "SUN", energy=SUN[2], local2world=hg.object_pose([0, 0, 5], [SUN[0], 0, SUN[1]])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(CAMERA[2], *size, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at(CAMERA[0], CAMERA[1]))
    return scene


def render_cycles(objects: list[dict[str, Any]], scene: Any, mode: str, spp: int, work: Path) -> dict[str, np.ndarray]:
    """Cycles' passes (name -> H x W x C float) of the scene in ``mode`` (tools/dust_cycles_scene.py)."""
    import mitsuba as mi
    from blender_side import exr_passes, run_blender_side

    arrays = {f"{o['name']}.{key}": o[key] for o in objects for key in ("vertices", "faces", "uvs", "normals")}
    np.savez(work / "scene.npz", **arrays)
    intr = scene.camera.intrinsics
    spec = {"mode": mode, "spp": spp, "bounces": 3, "resolution": [intr.width, intr.height], "world": list(WORLD),
            "objects": [{"name": o["name"], **BASE, "dust": o["dust"]} for o in objects],
            "sun": {"energy": scene.lights[0].energy, "local2world": scene.lights[0].local2world.tolist()},
            "camera": {"matrix_world": (scene.camera.keypoints[0] @ np.diag([1.0, -1, -1, 1])).tolist(),
                       "lens": float(intr.K[0, 0] * 36.0 / intr.width)}}
    (work / "spec.json").write_text(json.dumps(spec))
    run_blender_side("dust_cycles_scene.py", [str(work / "scene.npz"), str(work / "spec.json"),
                                              str(work / f"{mode}.exr")], work)
    mi.set_variant("llvm_ad_rgb")
    return exr_passes(work / f"{mode}.exr")


def object_masks(scene: Any, margin: float = 0.85) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Per object, the pixels whose centre ray first hits it well inside its outline; and each pixel's world
    normal z there (analytic squares and spheres)."""
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], -1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    origin = pose[:3, 3]
    best, owner = np.full(u.shape, np.inf), np.full(u.shape, "", dtype=object)
    inner, normal_z = np.zeros(u.shape, bool), np.zeros(u.shape)
    for name, x, _, _, nz in PLANES:
        t = -origin[2] / np.minimum(rays[..., 2], -1e-12)
        hit_x, hit_y = origin[0] + t * rays[..., 0] - x, origin[1] + t * rays[..., 1] - PLANE_Y
        hit = (np.maximum(abs(hit_x), abs(hit_y)) < HALF) & (t < best)
        best[hit], owner[hit], normal_z[hit] = t[hit], name, 1.0
        inner[hit] = np.maximum(abs(hit_x), abs(hit_y))[hit] < margin * HALF
    for name, x, _ in SPHERES:
        oc = origin - np.array([x, SPHERE_Y, RADIUS + 0.03])
        b = rays @ oc
        closest2 = oc @ oc - b * b
        t = -b - np.sqrt(np.maximum(RADIUS ** 2 - closest2, 0.0))
        hit = (closest2 < RADIUS ** 2) & (t > 0) & (t < best)
        best[hit], owner[hit] = t[hit], name
        normal_z[hit] = ((oc[2] + t * rays[..., 2]) / RADIUS)[hit]
        inner[hit] = closest2[hit] < (margin * RADIUS) ** 2
    return {o["name"]: (owner == o["name"]) & inner for o in layout()}, normal_z


def hybridgen_weights(scene: Any, origin: np.ndarray, points: np.ndarray) -> np.ndarray:
    """hybridgen's dust weight where rays from ``origin`` first hit, aimed at ``points`` (N x 3)."""
    import drjit as dr
    import mitsuba as mi
    from principled_vs_cycles import hybridgen_settings

    from hybridgen.render.pathtrace.path_trace import PathTraceView

    view = PathTraceView(scene, hybridgen_settings(3), variant="llvm_ad_rgb")
    direction = points - origin
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    ray = mi.Ray3f(mi.Point3f(*[mi.Float(np.full(len(points), c, np.float32)) for c in origin]),
                   mi.Vector3f(*[mi.Float(direction[:, i].astype(np.float32)) for i in range(3)]))
    si = view.mi_scene.ray_intersect(ray)
    weight = si.bsdf(ray).eval_diffuse_reflectance(si, si.is_valid())
    dr.eval(weight)
    return np.asarray(weight.x, np.float64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--res", default="160x120")
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--store", type=Path, default=None, help="write sampled Cycles weights as a test table")
    ns = parser.parse_args()
    size = tuple(int(v) for v in ns.res.split("x"))
    objects = layout()
    with tempfile.TemporaryDirectory(prefix="dust-") as temp:
        look_scene = hybridgen_scene(objects, size, weight_mode=False)
        look = render_cycles(objects, look_scene, "look", ns.spp, Path(temp))
        weights = render_cycles(objects, look_scene, "weight", 1, Path(temp))
    from principled_vs_cycles import render_hybridgen

    import hybridgen as hg
    from hybridgen.render.raster.albedo_pass import AlbedoPass

    ours_look, _ = render_hybridgen(look_scene, "blender", ns.spp, 3)
    raster = hg.RasterView(look_scene)
    ours_albedo = AlbedoPass(raster).render(look_scene.camera.keypoints[0])
    ours_diffuse = AlbedoPass(raster, diffuse_color=True).render(look_scene.camera.keypoints[0])
    masks, _ = object_masks(look_scene)
    print(f"{'object':12s} {'Cycles mean RGB':>26s}   hybridgen / Cycles   albedo, diffuse_color / Cycles' DiffCol")
    for name, mask in masks.items():
        theirs, ours = look["Combined"][..., :3][mask].mean(0), ours_look[mask].mean(0)
        albedo = ours_albedo[mask].mean(0) / look["DiffCol"][mask].mean(0)
        diffuse = ours_diffuse[mask].mean(0) / look["DiffCol"][mask].mean(0)
        print(f"{name:12s} {' '.join(f'{c:8.4f}' for c in theirs)}   {' '.join(f'{r:6.3f}' for r in ours / theirs)}"
              f"   {' '.join(f'{r:6.3f}' for r in albedo)}, {' '.join(f'{r:6.3f}' for r in diffuse)}   ({mask.sum()} px)")
    report_weights(objects, look_scene, weights, ns.store)


def report_weights(objects: list[dict[str, Any]], look_scene: Any, passes: dict[str, np.ndarray],
                   store: Path | None) -> None:
    """Cycles' exact weights against hybridgen's at the same points, per object and facing class."""
    size = (look_scene.camera.intrinsics.width, look_scene.camera.intrinsics.height)
    origin = look_scene.camera.keypoints[0][:3, 3]
    hit = passes["Combined"][..., 3] > 0.5
    theirs, points = passes["Combined"][..., 0][hit], passes["Position"][hit]
    normal, uv = passes["Normal"][hit], passes["UV"][hit]
    ours = hybridgen_weights(hybridgen_scene(objects, size, weight_mode=True), origin, points)
    view = points - origin
    view /= np.linalg.norm(view, axis=1, keepdims=True)
    facing_z = np.sign(-(view * normal).sum(1)) * normal[:, 2]
    masks, _ = object_masks(look_scene, margin=1.0)
    owner = np.full(hit.shape, "", dtype=object)
    for name, mask in masks.items():
        owner[mask] = name
    owner = owner[hit]
    strengths = {o["name"]: o["dust"][0][0] for o in objects}
    print(f"\n{'object':12s} {'class':5s} {'n':>5s}  mean w Cycles/hybridgen  dusty share Cycles/hybridgen  max |dw|")
    for name in masks:
        for label, cls in (("up", facing_z > 0.8), ("side", abs(facing_z) < 0.35)):
            pick = (owner == name) & cls
            if pick.sum() < 20:
                continue
            limit = 0.6 * max(strengths[name], 1e-9)
            print(f"{name:12s} {label:5s} {pick.sum():5d}  {theirs[pick].mean():8.4f} {ours[pick].mean():8.4f}"
                  f"         {np.mean(theirs[pick] >= limit):8.4f} {np.mean(ours[pick] >= limit):8.4f}"
                  f"          {np.abs(theirs[pick] - ours[pick]).max():.2e}")
    far = np.abs(theirs - ours) > 1e-3
    print(f"points: {hit.sum()}, |dw| > 1e-3 at {far.sum()} ({far.mean():.2%}), median |dw| "
          f"{np.median(np.abs(theirs - ours)):.1e}")
    if store is not None:
        rng = np.random.default_rng(0)
        known = np.flatnonzero(owner != "")
        keep = rng.choice(known, size=min(600, len(known)), replace=False)
        table = {"about": "Cycles (bpy 4.2) dust weights of BlenderProc's add_dust at sample points: tools/dust_vs_cycles.py",
                 "strength": [strengths[o] for o in owner[keep]],
                 "scale": [{o["name"]: o["dust"][0][1] for o in objects}[o] for o in owner[keep]],
                 **{key: [[float(f"{c:.9g}") for c in np.atleast_1d(row)] if np.ndim(row) else float(f"{row:.9g}")
                          for row in values[keep]]
                    for key, values in (("uv", uv), ("normal", normal), ("view", view), ("w", theirs))}}
        store.write_text(json.dumps(table) + "\n")
        print(f"stored {len(keep)} points in {store}")


if __name__ == "__main__":
    main()
