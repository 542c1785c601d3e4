"""Light units against analytic irradiance, and every light type and the HDRI world render sanely."""
from __future__ import annotations

import math

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView


@pytest.fixture(scope="module")
def variant() -> str:
    return choose_variant()


def _lambert_floor(albedo: float = 0.6) -> hg.Scene:
    scene = hg.Scene()
    floor = hg.make_primitive("plane", 50.0, name="floor", category_id=1, color=(albedo,) * 3)
    floor.material.specular = 0.0
    scene.add(floor)
    scene.world.strength = 0.0
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.2, 16, 16)
    scene.camera.add_keypoint(hg.look_at([0.0, -0.3, 3.0], [0, 0, 0]))
    return scene


def _centre(scene: hg.Scene, variant: str, spp: int = 64) -> float:
    image = PathTraceView(scene, PathTraceSettings(samples=spp, max_bounces=0), variant=variant).render(
        scene.camera.keypoints[0], seed=2)
    assert np.isfinite(image).all()
    return float(image[6:10, 6:10].mean())


def test_point_light_power_in_watts(variant):
    """P watts at height h above a Lambertian floor: radiance albedo/pi * P/(4 pi h^2) right below it."""
    albedo, power, height = 0.6, 200.0, 2.0
    scene = _lambert_floor(albedo)
    scene.add_light(hg.Light("bulb", "POINT", energy=power, local2world=hg.object_pose([0, 0, height])))
    expected = albedo / math.pi * power / (4 * math.pi * height ** 2)
    assert _centre(scene, variant) == pytest.approx(expected, rel=0.03)


def test_sun_strength_is_irradiance(variant):
    albedo, strength = 0.6, 3.0
    scene = _lambert_floor(albedo)
    scene.add_light(hg.Light("sun", "SUN", energy=strength, local2world=hg.object_pose([0, 0, 5], [0.5, 0, 0])))
    expected = albedo / math.pi * strength * math.cos(0.5)  # shines along its rotated -z, 0.5 rad off vertical
    assert _centre(scene, variant) == pytest.approx(expected, rel=0.02)


def test_area_light_power(variant):
    """A small square AREA light far above the floor acts like a one-sided Lambertian emitter of power P."""
    albedo, power, height = 0.6, 500.0, 4.0
    scene = _lambert_floor(albedo)
    scene.add_light(hg.Light("panel", "AREA", energy=power, size=0.2, local2world=hg.object_pose([0, 0, height])))
    # radiance L = P / (A pi); irradiance below ~ L A / h^2
    expected = albedo / math.pi * power / math.pi / height ** 2
    assert _centre(scene, variant, spp=128) == pytest.approx(expected, rel=0.05)


def test_spot_light_lights_only_its_cone(variant):
    scene = _lambert_floor()
    scene.add_light(hg.Light("spot", "SPOT", energy=300.0, spot_size=0.4, local2world=hg.object_pose([0, 0, 2.0])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.4, 32, 32)
    image = PathTraceView(scene, PathTraceSettings(samples=16, max_bounces=0), variant=variant).render(
        scene.camera.keypoints[0], seed=1)
    assert image[14:18, 14:18].mean() > 0.05 and image[:3, :3].mean() == 0.0


def test_hdri_world_matches_constant_world(variant, tmp_path):
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_variant import activate

    activate(variant)
    path = tmp_path / "sky.exr"
    mi.Bitmap(np.full((16, 32, 3), 0.4, np.float32)).write(str(path))
    constant = _lambert_floor()
    constant.world.color, constant.world.strength = (0.4, 0.4, 0.4), 1.5
    hdri = _lambert_floor()
    hdri.world.hdri_path, hdri.world.strength, hdri.world.hdri_rotation = str(path), 1.5, 0.7
    a, b = _centre(constant, variant), _centre(hdri, variant)
    assert a == pytest.approx(0.6 * 0.4 * 1.5, rel=0.02) and b == pytest.approx(a, rel=0.02)
    hdri.world.hdri_path = str(tmp_path / "missing.exr")
    with pytest.raises(hg.InputError, match="HDRI file not found"):
        PathTraceView(hdri, variant=variant)


def test_negative_light_energy_is_rejected():
    with pytest.raises(ValueError, match="energy"):
        hg.Light("bad", "POINT", energy=-1.0)
