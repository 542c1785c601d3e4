"""``caustics_refractive`` (Cycles' option; render/pathtrace/clamped_path.py): refraction dropped where a diffuse bounce led."""
from __future__ import annotations

import numpy as np

import hybridgen as hg
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


def _lamp_in_glass() -> hg.Scene:
    """A small emissive sphere inside a roughness-0 glass ball over a Lambertian floor, black world: every
    photon reaches the floor through the glass, so the floor is lit only by refractive caustics."""
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 20.0, name="floor", category_id=1, color=(0.7, 0.7, 0.7))
    floor.material.specular = 0.0
    scene.add(floor)
    ball = hg.make_primitive("sphere", 0.5, name="glass", category_id=2, color=(1.0, 1.0, 1.0),
                             local2world=hg.object_pose([0.0, 0.0, 0.6]))
    ball.material.transmission, ball.material.roughness, ball.material.ior = 1.0, 0.0, 1.45
    scene.add(ball)
    lamp = hg.make_primitive("sphere", 0.15, name="lamp", category_id=3, color=(0.0, 0.0, 0.0),
                             local2world=hg.object_pose([0.0, 0.0, 0.6]))
    lamp.material.emission, lamp.material.emission_strength = (1.0, 0.9, 0.8), 30.0
    scene.add(lamp)
    scene.world.strength = 0.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 32, 24)
    scene.camera.add_keypoint(hg.look_at([2.0, -1.5, 1.6], [0.0, 0.0, 0.3]))
    return scene


def _render(scene: hg.Scene, caustics: bool, jit_variant: str) -> np.ndarray:
    view = PathTraceView(scene, PathTraceSettings(samples=32, caustics_refractive=caustics, clamp_indirect=0.0),
                         variant=jit_variant)
    assert view.own_integrator
    return view.render(scene.camera.keypoints[0], seed=3)


def test_floor_lit_only_through_glass_goes_dark_without_refractive_caustics(jit_variant):
    scene = _lamp_in_glass()
    ids = hg.RasterView(scene).render(scene.camera.keypoints[0], ["instance_segmaps"])["instance_segmaps"]
    floor, glass = ids == 1, ids == 2
    assert floor.sum() > 100 and glass.sum() > 20
    on, off = _render(scene, True, jit_variant), _render(scene, False, jit_variant)
    assert on[floor].mean() > 0.01  # the caustic (and the glow around the ball) lights the floor
    assert off[floor].max() == 0.0  # no other light reaches it
    # the camera sees the lamp through the glass either way: no diffuse bounce before the refraction
    assert off[glass].mean() > 0.5 * on[glass].mean() > 0.0


def test_scene_without_refracting_surfaces_is_unchanged(jit_variant):
    """Only refraction after a diffuse bounce is dropped: a scene of diffuse, glossy and metal surfaces renders
    the same (same samples; equal up to the float rounding of two kernels)."""
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 20.0, name="floor", category_id=1, color=(0.6, 0.6, 0.6))
    scene.add(floor)
    metal = hg.make_primitive("sphere", 0.4, name="metal", category_id=2, color=(0.9, 0.8, 0.6),
                              local2world=hg.object_pose([0.3, 0.0, 0.4]))
    metal.material.metallic, metal.material.roughness = 1.0, 0.15
    scene.add(metal)
    scene.lights.append(hg.Light("lamp", "POINT", energy=800.0, local2world=hg.object_pose([0, -1.0, 2.0])))
    scene.world.strength = 0.2
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, 24, 16)
    scene.camera.add_keypoint(hg.look_at([2.0, -1.5, 1.4], [0.0, 0.0, 0.3]))
    on, off = _render(scene, True, jit_variant), _render(scene, False, jit_variant)
    assert on.mean() > 0.05
    np.testing.assert_allclose(on, off, rtol=1e-5, atol=1e-7)


def test_refractive_caustics_are_on_by_default_as_in_cycles(jit_variant):
    import mitsuba as mi

    mi.set_variant(jit_variant)
    assert PathTraceSettings().integrator_for(jit_variant)["caustics_refractive"] is True
    assert PathTraceSettings(caustics_refractive=False).integrator_for(jit_variant)["caustics_refractive"] is False
