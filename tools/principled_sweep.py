"""The Principled material sweeps tools/principled_vs_cycles.py renders in hybridgen and Cycles: their materials,
the sphere-grid scenes, the small test views and the per-object masks (analytic ray casts).

The scene: rows of :data:`COLUMNS` spheres (0.36 m across) over a grey Lambertian floor, each sphere one material
of a sweep (:data:`GROUPS`), lit either by a sun (3 W/m^2, 50 degrees above the horizon) under a uniform grey-blue
sky (``sun``), by a square area light (:data:`AREA_LIGHT`: 1 m edge, 60 W, 2.5 m above the floor, tilted towards
the spheres) under a black world (``area``), by the generated sky HDRI of tools/color_quality.py with its small
bright sun (``hdri``), or by nothing (``dark``: black world, no lights, for emissive spheres). Spheres with a normal
map (the ``bumps`` value of a texture field) are UV spheres (:func:`uv_sphere`) carrying :func:`bumps`; the others
hybridgen's icosphere.
Units: metres, linear RGB.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SWEEP: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # (name, base color, Material fields / Principled extras)
    ("red_s0", (0.8, 0.1, 0.1), dict(roughness=0.4, specular=0.0)),
    ("red_s05_r02", (0.8, 0.1, 0.1), dict(roughness=0.2, specular=0.5)),
    ("red_s05_r06", (0.8, 0.1, 0.1), dict(roughness=0.6, specular=0.5)),
    ("red_s1_r03", (0.8, 0.1, 0.1), dict(roughness=0.3, specular=1.0)),
    ("blue_s05_r04", (0.05, 0.1, 0.4), dict(roughness=0.4, specular=0.5)),
    ("white_s05_r05", (0.9, 0.9, 0.85), dict(roughness=0.5, specular=0.5)),
    ("grey_s05_r09", (0.5, 0.5, 0.5), dict(roughness=0.9, specular=0.5)),
    ("grey_s1_r01", (0.5, 0.5, 0.5), dict(roughness=0.1, specular=1.0)),
    ("dark_s05_r03", (0.03, 0.03, 0.03), dict(roughness=0.3, specular=0.5)),
    ("gold_m1_r03", (1.0, 0.77, 0.34), dict(roughness=0.3, metallic=1.0)),
    ("grey_m1_r06", (0.6, 0.6, 0.6), dict(roughness=0.6, metallic=1.0)),
    ("copper_m1_r1", (0.95, 0.64, 0.54), dict(roughness=1.0, metallic=1.0)),
    ("green_m05_r04", (0.2, 0.7, 0.3), dict(roughness=0.4, metallic=0.5)),
    ("red_coat", (0.8, 0.1, 0.1), dict(roughness=0.5, specular=0.5, extra=dict(coat_weight=1.0, coat_roughness=0.1))),
    ("blue_coat_tint", (0.1, 0.2, 0.6), dict(roughness=0.6, specular=0.5, extra=dict(
        coat_weight=0.7, coat_roughness=0.3, coat_tint=(1.0, 0.8, 0.5)))),
    ("glass_r02", (1.0, 1.0, 1.0), dict(roughness=0.2, transmission=1.0, ior=1.5)),
    ("green_glass_r05", (0.3, 0.9, 0.4), dict(roughness=0.5, transmission=1.0, ior=1.45)),
    ("aniso_metal", (0.9, 0.9, 0.9), dict(roughness=0.4, metallic=1.0, extra=dict(anisotropic=0.8))),
]
SWEEP_LAYERS: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # sheen (Blender 4's microfiber sheen) and subsurface (hybridgen: Cycles' diffuse fallback; Cycles: its walk)
    ("red_sheen1_r05", (0.8, 0.1, 0.1), dict(roughness=0.5, specular=0.5, extra=dict(sheen_weight=1.0))),
    ("velvet_sheen1_r03", (0.05, 0.02, 0.1), dict(roughness=0.7, specular=0.0, extra=dict(
        sheen_weight=1.0, sheen_roughness=0.3, sheen_tint=(0.9, 0.7, 1.0)))),
    ("blue_sheen05_r08", (0.1, 0.2, 0.6), dict(roughness=0.6, specular=0.5, extra=dict(
        sheen_weight=0.5, sheen_roughness=0.8, sheen_tint=(1.0, 0.9, 0.7)))),
    ("black_sheen1_r02", (0.0, 0.0, 0.0), dict(roughness=0.5, specular=0.0, extra=dict(
        sheen_weight=1.0, sheen_roughness=0.2))),
    ("gold_coat_sheen", (0.6, 0.45, 0.15), dict(roughness=0.4, specular=0.5, extra=dict(
        coat_weight=1.0, coat_roughness=0.2, sheen_weight=1.0, sheen_roughness=0.4))),
    ("skin_ss1_r0", (0.8, 0.5, 0.4), dict(roughness=0.5, specular=0.5, extra=dict(
        subsurface_weight=1.0, subsurface_scale=0.0))),
    ("skin_ss05_rw", (0.8, 0.5, 0.4), dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=0.5))),
    ("skin_ss1_rw", (0.8, 0.5, 0.4), dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=1.0))),
    ("skin_ss1_burley", (0.8, 0.5, 0.4), dict(roughness=0.5, specular=0.5, extra=dict(
        subsurface_weight=1.0, subsurface_method="BURLEY"))),
    ("skin_ss1_amass", (0.8, 0.5, 0.4), dict(roughness=0.5, specular=0.003, extra=dict(
        subsurface_weight=1.0, subsurface_scale=0.2, subsurface_ior=2.5, subsurface_method="RANDOM_WALK_SKIN"))),
]
SKIN = (0.8, 0.5, 0.4)
SWEEP_SUBSURFACE: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # Cycles' random walk against hybridgen's diffuse fallback: weight x radius scale (the radius (1, 0.2, 0.1) m,
    # Blender's default, times the scale; the spheres are 0.36 m across), and what else changes Cycles' walk
    (f"ss{name}", SKIN, dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=w, subsurface_scale=scale)))
    for name, w, scale in (("0", 0.0, 0.05), ("05_s001", 0.5, 0.01), ("05_s005", 0.5, 0.05), ("05_s02", 0.5, 0.2),
                           ("1_s001", 1.0, 0.01), ("1_s005", 1.0, 0.05), ("1_s02", 1.0, 0.2))
] + [
    ("ss1_s005_aniso08", SKIN, dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=1.0,
                                                                            subsurface_anisotropy=0.8))),
    ("ss1_s005_ior2", SKIN, dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=1.0, subsurface_ior=2.0))),
    ("ss1_s005_spec0", SKIN, dict(roughness=0.5, specular=0.0, extra=dict(subsurface_weight=1.0))),
    ("ss1_s005_r01", SKIN, dict(roughness=0.1, specular=0.5, extra=dict(subsurface_weight=1.0))),
    ("ss1_s005_skin", SKIN, dict(roughness=0.5, specular=0.5, extra=dict(subsurface_weight=1.0,
                                                                         subsurface_method="RANDOM_WALK_SKIN"))),
]
DARK = (0.03, 0.03, 0.03)
COAT1 = dict(coat_weight=1.0, coat_roughness=0.25)
SWEEP_COAT_NORMAL: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # UV spheres with the strong procedural normal map :func:`bumps` on Normal and / or Coat Normal (Blender: a Normal
    # Map node in tangent space on the sphere's UV map linked to the input)
    ("cn_nocoat_map", (0.6, 0.1, 0.1), dict(roughness=0.3, specular=0.5, normal_texture="bumps")),
    ("cn_base_map", DARK, dict(roughness=0.4, specular=0.5, normal_texture="bumps", extra=COAT1)),
    ("cn_coat_map", DARK, dict(roughness=0.4, specular=0.5, coat_normal_texture="bumps", extra=COAT1)),
    ("cn_both_maps", DARK, dict(roughness=0.4, specular=0.5, normal_texture="bumps", coat_normal_texture="bumps",
                                extra=COAT1)),
    ("cn_red_base_map", (0.8, 0.1, 0.1), dict(roughness=0.5, specular=0.5, normal_texture="bumps", extra=dict(
        coat_weight=1.0, coat_roughness=0.3))),
    ("cn_sheen_coat_map", (0.3, 0.2, 0.1), dict(roughness=0.5, specular=0.5, normal_texture="bumps", extra=dict(
        coat_weight=0.5, coat_roughness=0.3, sheen_weight=1.0, sheen_roughness=0.4))),
]
EMISSIVE = dict(roughness=0.4, specular=0.5, emission=(1.0, 0.6, 0.3), emission_strength=2.0)
SWEEP_EMISSION: list[tuple[str, tuple[float, float, float], dict[str, Any]]] = [
    # emissive spheres (Principled Emission (1, 0.6, 0.3) x 2) under coat and sheen; seen under the ``dark`` lighting
    ("em_c0", (0.2, 0.2, 0.2), dict(EMISSIVE)),
    ("em_c05", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(coat_weight=0.5))),
    ("em_c1", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(coat_weight=1.0))),
    ("em_c1_tint", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(coat_weight=1.0, coat_tint=(1.0, 0.7, 0.4)))),
    ("em_c1_r05_ior2", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(coat_weight=1.0, coat_roughness=0.5,
                                                                  coat_ior=2.0))),
    ("em_sheen1", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(sheen_weight=1.0, sheen_roughness=0.3))),
    ("em_sheen_coat", (0.2, 0.2, 0.2), dict(EMISSIVE, extra=dict(sheen_weight=1.0, sheen_roughness=0.3,
                                                                 coat_weight=1.0, coat_tint=(0.8, 0.9, 1.0)))),
]
GROUPS = {"principled": SWEEP, "layers": SWEEP_LAYERS, "subsurface": SWEEP_SUBSURFACE,
          "coat_normal": SWEEP_COAT_NORMAL, "emission": SWEEP_EMISSION}
"""The sweeps, each rendered as a scene of its own (``--group``): the first sweep of issue 32, the sheen /
subsurface one (both stored for the tests), subsurface weights x radius scales (measured for the docs), the coat
normal rule (a normal map on Normal and / or Coat Normal of coated spheres) and emission under coat and sheen."""
GROUP_LIGHTINGS = {"emission": ("dark",)}
"""Lightings a group is rendered under when not the default :data:`LIGHTINGS` (``dark``: black world, no lights:
only the spheres' own emission)."""
COLUMNS, SPACING, DIAMETER = 6, 0.46, 0.36
LIGHTINGS = ("sun", "area", "hdri")
ALL_LIGHTINGS = ("sun", "area", "hdri", "dark")
AREA_LIGHT = dict(location=(0.4, -0.5, 2.5), rotation=(math.radians(16.0), 0.0, math.radians(36.0)), size=1.0,
                  energy=60.0)
"""The ``area`` lighting's light: a square Blender AREA light (Cycles: shape SQUARE, spread 180 degrees, one-sided)
of edge ``size`` (m) and power ``energy`` (W) at ``location`` (m, world), turned by the XYZ Euler ``rotation``
(rad) so its emitting side (local -z) faces the grid's centre from above the camera's side: about 3 W/m^2 on the
spheres' tops, as the sun, and a highlight in every glossy sphere."""


TEST_OBJECTS = ("red_s1_r03", "white_s05_r05", "grey_m1_r06", "copper_m1_r1")
"""The spheres of the small test view (``--store``; tests/render/test_principled_vs_cycles.py): objects whose
color Mitsuba's principled got 7-55 % wrong."""


TEST_AREA_OBJECTS = ("grey_s1_r01", "white_s05_r05", "gold_m1_r03", "red_coat")
"""The spheres of the area-light test view: the area light's square mirrored sharply (roughness 0.1, a coat of
0.1) and broadly (roughness 0.3 metal, 0.5 dielectric), compared with Cycles' image pixel by pixel too."""


TEST_GLASS_OBJECTS = ("green_glass_r05", "glass_r02")
"""The spheres of the glass test view (under the HDRI): rough refraction lit by the HDRI's small sun, where Cycles
values direction pairs no microfacet connects (docs/principled_bsdf.md, "Refraction pairs"; 0.95 of Cycles without)
and a less rough clear glass."""


TEST_COAT_NORMAL_OBJECTS = ("cn_base_map", "cn_coat_map", "cn_red_base_map", "cn_sheen_coat_map")
"""The spheres of the coat-normal test view: the base's map alone, the coat's alone, a red base under a coat, and
sheen over a half coat (the sheen's mixed normal)."""
TEST_EMISSION_OBJECTS = ("em_c0", "em_c1", "em_c1_tint", "em_sheen_coat")
"""The spheres of the emission test view (``dark`` lighting): no layer, a coat, a tinted coat, sheen over coat."""


TEST_LAYER_OBJECTS = ("red_sheen1_r05", "velvet_sheen1_r03", "skin_ss1_r0", "aniso_metal")
"""The spheres of the second test view: sheen over a dielectric and over a near-black base; subsurface without a
radius (which Cycles renders with its diffuse fallback, as hybridgen does); anisotropic metal (Blender's default
radial tangent)."""


def sweep(names: tuple[str, ...] | None = None,
          group: str = "principled") -> list[tuple[str, tuple[float, float, float], dict[str, Any]]]:
    """The entries of the sweep ``group`` (:data:`GROUPS`), or those named ``names`` (of any group), in that
    order."""
    if names is None:
        return list(GROUPS[group])
    entries = {entry[0]: entry for entries in GROUPS.values() for entry in entries}
    return [entries[name] for name in names]


def sphere_centers(count: int) -> list[tuple[float, float, float]]:
    """World centres (m) of ``count`` spheres: rows of :data:`COLUMNS` along x, row 0 nearest the camera (-y)."""
    columns = min(COLUMNS, count)
    rows = math.ceil(count / columns)
    return [((i % columns - (columns - 1) / 2) * SPACING, (i // columns - (rows - 1) / 2) * SPACING, DIAMETER / 2)
            for i in range(count)]


def build_scene(lighting: str, width: int, height: int, workdir: Path,
                names: tuple[str, ...] | None = None, group: str = "principled") -> Any:
    """The sweep scene of ``group`` (or only the spheres ``names``, in one row, framed closer) under
    ``lighting`` (:data:`ALL_LIGHTINGS`) at ``width`` x ``height`` px."""
    import hybridgen as hg

    scene = hg.Scene()
    floor = hg.make_primitive("plane", 6.0, name="floor", category_id=1, color=(0.5, 0.5, 0.5))
    floor.material.specular = 0.0
    scene.add(floor)
    entries = sweep(names, group)
    for index, ((name, color, values), center) in enumerate(zip(entries, sphere_centers(len(entries)))):
        mapped = any(value == "bumps" for value in values.values())
        if mapped:  # a UV sphere for the normal maps
            ball = uv_sphere(name, DIAMETER)
            ball.category_id, ball.local2world = index + 2, hg.object_pose(list(center))
            ball.material.base_color = (*color, 1.0)
        else:
            ball = hg.make_primitive("sphere", DIAMETER, name=name, category_id=index + 2, color=color,
                                     local2world=hg.object_pose(list(center)))
        for key, value in values.items():
            if key == "extra":
                ball.material.extra = dict(value)
            else:
                setattr(ball.material, key, bumps() if value == "bumps" else value)
        scene.add(ball)
    if lighting == "dark":
        scene.world.color, scene.world.strength = (0.0, 0.0, 0.0), 0.0
    elif lighting == "sun":
        scene.world.color, scene.world.strength = (0.3, 0.35, 0.45), 1.0
        scene.add_light(hg.Light("sun", "SUN", energy=3.0,
                                 local2world=hg.object_pose([0, 0, 5], [math.radians(40), 0, math.radians(30)])))
    elif lighting == "area":  # a black world: Cycles' lights let rays through, hybridgen's rectangle would hide it
        scene.world.color, scene.world.strength = (0.0, 0.0, 0.0), 0.0
        pose = hg.object_pose(list(AREA_LIGHT["location"]), list(AREA_LIGHT["rotation"]))
        scene.add_light(hg.Light("area", "AREA", energy=AREA_LIGHT["energy"], size=AREA_LIGHT["size"],
                                 local2world=pose))
    elif lighting == "hdri":
        sys.path.insert(0, str(REPO / "tools"))
        from color_quality import sky_hdri

        scene.world.hdri_path = str(sky_hdri(workdir / "sky.exr"))
        scene.world.strength, scene.world.hdri_rotation = 1.0, 0.3
    else:
        raise ValueError(f"lighting must be one of {ALL_LIGHTINGS}, got {lighting!r}")
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.75, width, height, clip_start=0.01)
    location = [0.0, -2.6, 1.9] if names is None else [0.0, -1.9, 1.1]
    scene.camera.add_keypoint(hg.look_at(location, [0.0, 0.05, 0.1]))
    return scene


def uv_sphere(name: str, diameter: float, segments: int = 64, rings: int = 32) -> Any:
    """A smooth sphere (m, object frame, centred) with a latitude-longitude UV map: u = azimuth / 2 pi from +X
    towards +Y, v = 1 at the north pole (+Z) and 0 at the south pole; the seam's vertices doubled."""
    import hybridgen as hg

    theta = np.pi * np.arange(rings + 1) / rings
    phi = 2.0 * np.pi * np.arange(segments + 1) / segments
    tt, pp = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1).reshape(-1, 3)
    uvs = np.stack([pp / (2.0 * np.pi), 1.0 - tt / np.pi], -1).reshape(-1, 2)
    faces = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            if i > 0:
                faces.append([a, b, a + 1])
            if i < rings - 1:
                faces.append([a + 1, b, b + 1])
    return hg.MeshObject(name, normals * diameter / 2.0, np.array(faces), vertex_normals=normals, uvs=uvs)


def bumps(width: int = 512, height: int = 256, strength: float = 0.8) -> np.ndarray:
    """The sweep's normal map (uint8 H x W x 3, OpenGL tangent space: x along +u, y along +v, rows top-down):
    an egg-crate of 16 x 8 bumps whose normals tilt up to atan(``strength``) (39 degrees)."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    a, b = np.meshgrid(2.0 * np.pi * 16 * u, 2.0 * np.pi * 8 * v)
    n = np.stack([-strength * np.cos(a) * np.sin(b), -strength * np.sin(a) * np.cos(b), np.ones_like(a)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.round((n * 0.5 + 0.5) * 255.0).astype(np.uint8)


def object_masks(scene: Any, names: tuple[str, ...] | None = None, margin: float = 0.8,
                 group: str = "principled") -> dict[str, np.ndarray]:
    """Per object name, the pixels (bool H x W) whose centre ray first hits it, spheres only where the ray passes
    within ``margin`` x radius of the centre (away from silhouettes and from the tessellation's edge)."""
    intr = scene.camera.intrinsics
    pose = scene.camera.keypoints[0]
    v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], axis=-1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    origin = pose[:3, 3]
    distance = np.full(u.shape, np.inf)
    owner = np.full(u.shape, -1)
    inner = np.zeros(u.shape, bool)
    radius = DIAMETER / 2
    entries = sweep(names, group)
    for index, center in enumerate(sphere_centers(len(entries))):
        oc = origin - np.asarray(center)
        b = rays @ oc
        closest2 = oc @ oc - b * b
        t = -b - np.sqrt(np.maximum(radius * radius - closest2, 0.0))
        hit = (closest2 < radius * radius) & (t > 0) & (t < distance)
        distance[hit], owner[hit] = t[hit], index + 1
        inner[hit] = closest2[hit] < (margin * radius) ** 2
    t_floor = -origin[2] / np.minimum(rays[..., 2], -1e-9)
    floor = (rays[..., 2] < 0) & (t_floor < distance) & (np.abs(origin[0] + t_floor * rays[..., 0]) < 2.5)
    masks = {"floor": floor}
    for index, (name, _, _) in enumerate(entries):
        masks[name] = (owner == index + 1) & inner & ~floor
    return masks


def object_means(image: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, list[float]]:
    """Mean linear RGB of ``image`` over each mask."""
    return {name: image[mask].astype(np.float64).mean(axis=0).tolist() for name, mask in masks.items()}
