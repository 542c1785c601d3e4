"""Singular surfaces as in Cycles (render/pathtrace/clamped_path.py): principled lobes of roughness <= 0.00376 get no
next-event estimation, and light they reflect is found by BSDF sampling at full weight."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace import clamped_path
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
from hybridgen.scene.material import Material

LOOK_DOWN = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 1.0], [0, 0, 0, 1]])  # at z = 1 looking down


def test_threshold_is_cycles_roughness_sq_thresh():
    # Cycles: alpha_x alpha_y <= 2e-10 with alpha = roughness^2
    assert clamped_path.SINGULAR_ROUGHNESS ** 4 == pytest.approx(2e-10)
    assert clamped_path.SINGULAR_ROUGHNESS == pytest.approx(0.0037606, abs=1e-6)


def test_singular_lanes_of_hybridgen_bsdfs(jit_variant):
    """hybridgen's own BSDFs (twosided principled with the glossy filter's roughness wrapper, glass, diffuse):
    metal and glass singular at roughness 0 and 0.0037, not at 0.004 or 0.2, never a diffuse one nor a principled
    one with a diffuse lobe (sharp plastic, half metal: its diffuse light needs NEE); the glossy filter's floor
    (si.time) lifts a sharp lobe out of it, as Cycles' blur_glossy sets SD_BSDF_HAS_EVAL again."""
    import mitsuba as mi

    mi.set_variant(jit_variant)
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    materials = [Material(metallic=1.0, roughness=0.0), Material(metallic=1.0, roughness=0.0037),
                 Material(metallic=1.0, roughness=0.004), Material(roughness=0.2, specular=0.5),
                 Material(transmission=1.0, roughness=0.0, ior=1.5), Material(specular=0.0),
                 Material(roughness=0.0, specular=0.5), Material(metallic=0.5, roughness=0.0)]
    shapes = {f"s{i}": {"type": "sphere", "center": [3.0 * i, 0, 0], "radius": 1.0,
                        "bsdf": bsdf_dict(m, f"s{i}")} for i, m in enumerate(materials)}
    scene = mi.load_dict({"type": "scene", **shapes})
    n = len(materials)
    ray = mi.Ray3f(mi.Point3f([3.0 * i for i in range(n)], [0.0] * n, [-5.0] * n), mi.Vector3f(0, 0, 1))
    si = scene.ray_intersect(ray)
    assert np.all(np.array(si.is_valid()))
    singular = np.array(clamped_path.is_singular(si.bsdf(ray), si))
    np.testing.assert_array_equal(singular, [True, True, False, False, True, False, False, False])
    si.time = mi.Float(0.01)  # a roughness floor after a rough bounce
    np.testing.assert_array_equal(np.array(clamped_path.is_singular(si.bsdf(ray), si)), [False] * n)


def _mirror_scene(*, panel: bool, roughness: float = 0.0) -> hg.Scene:
    scene = hg.Scene()
    scene.world.strength = 0.0
    mirror = hg.make_primitive("plane", 4.0, name="mirror", category_id=1, color=(0.8, 0.8, 0.8))
    mirror.material.metallic, mirror.material.roughness = 1.0, roughness
    scene.add(mirror)
    if panel:  # an emitting panel above the camera, facing down (Mitsuba area emitters emit along +normal)
        light = hg.make_primitive("plane", 6.0, name="panel", category_id=2, color=(0.0, 0.0, 0.0),
                                  local2world=hg.object_pose([0, 0, 2.0], [np.pi, 0, 0]))
        light.material.specular, light.material.emission, light.material.emission_strength = 0.0, (1.0, 1.0, 1.0), 1.5
        scene.add(light)
    else:
        scene.add_light(hg.Light("lamp", "POINT", energy=100.0, local2world=hg.object_pose([0.02, 0.01, 1.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.3, 8, 6)
    return scene


def test_sharp_mirror_shows_no_point_light_and_the_full_reflected_panel(jit_variant):
    """A roughness-0 metal mirror (F0 = base 0.8) under a black world: a point light is not reflected at all
    (Cycles: no NEE on a singular closure, and a point light cannot be hit), and an emitting panel of radiance
    1.5 is reflected at full weight: F x 1.5 with Schlick's F at these near-normal angles (< 9 deg: F - F0 <
    1e-6)."""
    settings = PathTraceSettings(samples=64)
    dark = PathTraceView(_mirror_scene(panel=False), settings, variant=jit_variant).render(LOOK_DOWN, seed=3)
    assert float(np.abs(dark).max()) == 0.0
    panel = PathTraceView(_mirror_scene(panel=True), settings, variant=jit_variant).render(LOOK_DOWN, seed=3)
    np.testing.assert_allclose(panel.reshape(-1, 3), np.full((48, 3), 0.8 * 1.5), rtol=1e-3)


def _grid_of_materials() -> list[Material]:
    """Constant materials around the singular threshold (also values that float32 rounds onto or off it), and maps
    of roughness and metallic with texels on both sides of it (a 4 x 4 checker of 0 and 1, each square 4 x 4
    texels, so bilinear lookups inside a square are exactly 0 or 1)."""
    checker = np.kron(np.indices((4, 4)).sum(axis=0) % 2, np.ones((4, 4), int)).astype(np.uint8) * 255
    out = [Material(metallic=metallic, transmission=transmission, roughness=roughness, specular=specular, ior=1.5)
           for metallic in (0.0, 0.5, 1.0) for transmission in (0.0, 1.0) for roughness in (0.0, 0.0037, 0.004, 0.2)
           for specular in (0.0, 0.5)]
    threshold = clamped_path.SINGULAR_ROUGHNESS  # values that round across the boundaries in float32
    out += [Material(metallic=1 - 1e-9, roughness=0.0), Material(transmission=1 - 1e-9, roughness=0.0, ior=1.5),
            Material(metallic=1.0, roughness=float(np.nextafter(threshold, 1.0))),
            Material(metallic=1.0, roughness=threshold * (1 + 1e-9)), Material(metallic=1 - 1e-6, roughness=0.0),
            Material(metallic=1.0, roughness=threshold * (1 + 1e-5))]
    return out + [Material(metallic=1.0, roughness_texture=checker), Material(metallic=0.0, roughness_texture=checker),
                  Material(metallic_texture=checker, roughness=0.0), Material(metallic_texture=checker, roughness=0.2),
                  Material(metallic_texture=checker, roughness_texture=checker[::-1])]


def test_may_be_singular_holds_wherever_a_lane_is_singular(jit_variant):
    """The scene-level gate (clamped_path.may_be_singular) never says False for a material whose BSDF has a
    singular lane: each material on a sphere, hit by a 16 x 16 grid of rays over its texture; exact for constant
    materials (singular everywhere or nowhere), conservative for maps, which must have both kinds of lanes here
    (else this test could not fail)."""
    import mitsuba as mi

    mi.set_variant(jit_variant)
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    materials = _grid_of_materials()
    shapes = {f"s{i}": {"type": "sphere", "center": [3.0 * i, 0, 0], "radius": 1.0, "bsdf": bsdf_dict(m, f"s{i}")}
              for i, m in enumerate(materials)}
    scene = mi.load_dict({"type": "scene", **shapes})
    offsets = np.linspace(-0.7, 0.7, 16)
    x, y = np.meshgrid(offsets, offsets)
    for index, material in enumerate(materials):
        n = x.size
        ray = mi.Ray3f(mi.Point3f(3.0 * index + x.ravel(), y.ravel(), np.full(n, -5.0)), mi.Vector3f(0, 0, 1))
        si = scene.ray_intersect(ray)
        assert np.all(np.array(si.is_valid()))
        lanes = np.array(clamped_path.is_singular(si.bsdf(ray), si))
        mapped = material.roughness_texture is not None or material.metallic_texture is not None
        if mapped:
            assert lanes.any() == clamped_path.may_be_singular(material), material
            if clamped_path.may_be_singular(material) and material.roughness_texture is not None:
                assert not lanes.all(), material  # a map with rough texels: singular in parts only
        else:
            assert len(set(lanes.tolist())) == 1, material
            assert bool(lanes[0]) == clamped_path.may_be_singular(material), material


def _tabletop(sharp_metal: bool) -> hg.Scene:
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 4.0, name="floor", category_id=1, color=(0.6, 0.6, 0.6))
    ball = hg.make_primitive("sphere", 0.6, name="ball", category_id=2, color=(0.8, 0.3, 0.2),
                             local2world=hg.object_pose([0.0, 0.0, 0.3]))
    ball.material.roughness, ball.material.specular = 0.2, 0.5
    mirror = hg.make_primitive("cube", 0.3, name="mirror", category_id=3, color=(0.9, 0.9, 0.9),
                               local2world=hg.object_pose([0.5, 0.3, 0.15]))
    mirror.material.metallic, mirror.material.roughness = 1.0, 0.0 if sharp_metal else 0.3
    for obj in (floor, ball, mirror):
        scene.add(obj)
    scene.add_light(hg.Light("lamp", "POINT", energy=200.0, local2world=hg.object_pose([1.0, -1.0, 2.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 18)
    return scene


def test_skipping_the_singular_test_changes_no_value(jit_variant):
    """A scene without singular materials renders the same bytes with the per-lane test skipped (the gate's
    choice there) and forced on; a scene with a sharp mirror keeps the test on, and forcing it off there changes
    the image (the point light's highlight comes back), so the comparison can tell."""
    cam2world = hg.look_at([0.0, -2.0, 1.2], [0.0, 0.0, 0.2])
    for sharp, gate in ((False, False), (True, True)):
        scene = _tabletop(sharp)
        view = PathTraceView(scene, PathTraceSettings(samples=16), variant=jit_variant)
        integrator = view.mi_scene.integrator()
        assert integrator.singular_surfaces is gate
        chosen = view.render(cam2world, seed=5)
        integrator.singular_surfaces = not gate
        forced = view.render(cam2world, seed=5)
        if sharp:
            assert not np.array_equal(chosen, forced)
        else:
            np.testing.assert_array_equal(chosen, forced)
