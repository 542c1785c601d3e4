"""Emitters hidden from the camera (BlenderProc's make_emissive: 3D-FRONT ceilings and lamps).

A panel of base color rho (two-sided diffuse) emitting radiance L, lit from below by a sun of irradiance E
straight onto its underside and seen from below with 0 bounces, shows rho E / pi when its emission is
hidden from the camera and rho E / pi + L when not. The floor it lights receives the same light either way.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.config.notices import set_sink
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

RHO, SUN, L = np.array([0.2, 0.4, 0.6]), 2.0, 1.5
LOOK_UP = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.0], [0, 0, 0, 1]])    # at z = 1 looking up (+z)
LOOK_DOWN = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 1.0], [0, 0, 0, 1]])  # at z = 1 looking down


def _scene(hidden: bool, *, floor: bool) -> hg.Scene:
    scene = hg.Scene()
    scene.world.strength = 0.0
    panel = hg.make_primitive("plane", 3.0, name="ceiling", category_id=1, color=tuple(RHO))
    panel.local2world = hg.object_pose(location=[0, 0, 2.0])
    panel.material.specular, panel.material.emission, panel.material.emission_strength = 0.0, (1.0, 1.0, 1.0), L
    panel.material.emission_hidden_from_camera = hidden
    scene.add(panel)
    if floor:
        scene.add(hg.make_primitive("plane", 6.0, name="floor", category_id=2, color=(0.5, 0.5, 0.5)))
    else:  # a sun shining straight up onto the panel's underside (a SUN shines along its -z)
        scene.add_light(hg.Light("sun", "SUN", energy=SUN, local2world=np.diag([1.0, -1.0, -1.0, 1.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, 12, 8)
    return scene


def test_camera_sees_the_surface_not_the_emission():
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    settings = PathTraceSettings(samples=4, max_bounces=0)
    hidden = PathTraceView(_scene(True, floor=False), settings, variant=variant).render(LOOK_UP, seed=1)
    shown = PathTraceView(_scene(False, floor=False), settings, variant=variant).render(LOOK_UP, seed=1)
    lit = RHO * SUN / math.pi
    np.testing.assert_allclose(hidden.reshape(-1, 3), np.broadcast_to(lit, (96, 3)), rtol=1e-3)
    np.testing.assert_allclose(shown.reshape(-1, 3), np.broadcast_to(lit + L, (96, 3)), rtol=1e-3)


def test_hidden_emitter_lights_the_floor_as_before():
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    settings = PathTraceSettings(samples=64, max_bounces=0)
    hidden = PathTraceView(_scene(True, floor=True), settings, variant=variant).render(LOOK_DOWN, seed=2)
    shown = PathTraceView(_scene(False, floor=True), settings, variant=variant).render(LOOK_DOWN, seed=2)
    assert hidden.mean() > 0.1
    np.testing.assert_allclose(hidden.mean(axis=(0, 1)), shown.mean(axis=(0, 1)), rtol=0.02)


def test_scalar_variant_says_it_shows_them():
    lines: list[str] = []
    set_sink(lines.append)
    try:
        PathTraceView(_scene(True, floor=False), PathTraceSettings(samples=1, max_bounces=0), variant="scalar_rgb")
    finally:
        set_sink(None)
    assert any("hidden from the camera" in line for line in lines)


def test_bounce_rays_see_the_emission_alone():
    """Floor and panel only: light reaching the floor indirectly must have reflected off the panel (a flat floor
    does not see itself): panel -> floor -> panel -> floor -> camera, two bounces. A hidden emitter reflects
    nothing for such rays, so bounces add nothing; a visible one (emission on its BSDF) adds its reflection of
    the lit floor."""
    variant = choose_variant()
    if variant == "scalar_rgb":
        pytest.skip("needs a JIT Mitsuba variant")
    means = {}
    for hidden in (True, False):
        for bounces in (0, 2):
            view = PathTraceView(_scene(hidden, floor=True), PathTraceSettings(samples=64, max_bounces=bounces,
                                                                               clamp_indirect=0), variant=variant)
            means[hidden, bounces] = view.render(LOOK_DOWN, seed=3).mean()
    np.testing.assert_allclose(means[True, 2], means[True, 0], rtol=0.01)
    assert means[False, 2] > 1.02 * means[False, 0]  # measured: +3.2 %
