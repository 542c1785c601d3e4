"""Specular and emission maps in Mitsuba against analytic values.

- Emission: a plane whose emission texture holds four sRGB blocks, seen directly (0 bounces, black world),
  shows radiance = sRGB-decoded texel x emission_strength inside each block.
- Specular: Blender's Principled specular s is a dielectric reflectance of 0.08 x s at normal incidence. A
  black (no diffuse) plane lit by a sun straight above and seen from straight above reflects
  F0 x D(h) G / (4 cos cos) x E cos (h within a few degrees of n, where Fresnel is F0): blocks of s = 0, 0.5,
  1 show 0, 0.5 and 1 times a specular-1 plane's radiance there, each equal to a plane with that value.
"""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.config.material_config import apply_material_config
from hybridgen.render.pathtrace.material_emission import srgb_decode
from hybridgen.render.pathtrace.mitsuba_materials import specular_levels
from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

WIDTH, HEIGHT, FOCAL, DISTANCE = 32, 12, 40.0, 3.0
BLOCK_TEXELS = 4


@pytest.fixture(scope="module")
def variant() -> str:
    return choose_variant()


def _blocks(values: list) -> np.ndarray:
    """A 4 x (4 len(values)) texture of one block of 4x4 texels per value, left to right (along +u)."""
    return np.repeat(np.asarray(values)[None, :], BLOCK_TEXELS, axis=0).repeat(BLOCK_TEXELS, axis=1)


def _block_pixels(count: int) -> list[int]:
    """Image columns at the centres of ``count`` blocks of a 2 m plane at x in [-1, 1] (camera above the
    origin, image x along world +x)."""
    centres = -1.0 + (np.arange(count) + 0.5) * 2.0 / count
    return [int(round(WIDTH / 2 - 0.5 + FOCAL * x / DISTANCE)) for x in centres]


def _render(variant: str, material: hg.Material, *, sun: bool, bounces: int = 0) -> np.ndarray:
    scene = hg.Scene()
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    scene.add(hg.MeshObject("plane", [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]],
                            uvs=uvs, material=material))
    scene.world.strength = 0.0
    if sun:
        scene.add_light(hg.Light("sun", "SUN", energy=3.0, local2world=np.eye(4)))  # shines along -z: down
    K = np.array([[FOCAL, 0, WIDTH / 2 - 0.5], [0, FOCAL, HEIGHT / 2 - 0.5], [0, 0, 1]])
    scene.camera.intrinsics = hg.Intrinsics(K, WIDTH, HEIGHT)
    cam2world = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, DISTANCE], [0, 0, 0, 1]])
    view = PathTraceView(scene, PathTraceSettings(samples=4, max_bounces=bounces), variant=variant)
    return view.render(cam2world, seed=3)


def test_emission_map_seen_directly_is_texel_times_strength(variant):
    codes = np.array([[255, 0, 0], [0, 128, 0], [40, 90, 200], [255, 255, 255]], np.uint8)
    texture = _blocks(list(range(4)))
    image = codes[texture]  # 4 x 16 x 3 uint8
    strength = 2.5
    material = hg.Material(base_color=(0.0, 0.0, 0.0, 1.0), specular=0.0, emission_texture=image,
                           emission_strength=strength)
    radiance = _render(variant, material, sun=False)
    expected = srgb_decode(codes / 255.0) * strength
    for block, column in enumerate(_block_pixels(4)):
        seen = radiance[HEIGHT // 2 - 2:HEIGHT // 2 + 2, column].mean(axis=0)
        np.testing.assert_allclose(seen, expected[block], rtol=0.01, atol=1e-4)
    # emission x strength without a map is unchanged: a constant color
    plain = _render(variant, hg.Material(base_color=(0, 0, 0, 1), specular=0.0, emission=(0.2, 0.4, 0.8),
                                         emission_strength=strength), sun=False)
    np.testing.assert_allclose(plain[HEIGHT // 2, WIDTH // 2], np.array([0.2, 0.4, 0.8]) * strength, rtol=0.01)


def test_specular_map_scales_the_highlight_like_f0(variant):
    texture = _blocks([0, 128, 255]).astype(np.uint8)
    black = dict(base_color=(0.0, 0.0, 0.0, 1.0), roughness=0.6)
    mapped = _render(variant, hg.Material(specular_texture=texture, **black), sun=True, bounces=1)
    full = _render(variant, hg.Material(specular=1.0, **black), sun=True, bounces=1)
    half = _render(variant, hg.Material(specular=128 / 255, **black), sun=True, bounces=1)
    rows = slice(HEIGHT // 2 - 2, HEIGHT // 2 + 2)
    columns = _block_pixels(3)
    seen = [mapped[rows, c - 1:c + 2].mean(axis=(0, 1)) for c in columns]
    assert np.all(seen[0] < 1e-4)  # specular 0: no reflection at all (and no diffuse)
    reference = [full[rows, c - 1:c + 2].mean(axis=(0, 1)) for c in columns]
    assert reference[2].min() > 0.05
    # F0 = 0.08 x specular: the 128-block reflects 128/255 of a specular-1 surface there (near normal
    # incidence, where the Fresnel term is F0), and each block equals a uniform plane of its value
    np.testing.assert_allclose(seen[1] / reference[1], 128 / 255, rtol=0.02)
    np.testing.assert_allclose(seen[1], half[rows, columns[1] - 1:columns[1] + 2].mean(axis=(0, 1)), rtol=0.02)
    np.testing.assert_allclose(seen[2], reference[2], rtol=0.02)


def test_specular_levels_interpolate_within_the_maps_range():
    few = specular_levels(hg.Material(specular_texture=_blocks([0, 128, 255]).astype(np.uint8)), "o")
    assert few[0] == pytest.approx([0.0, 128 / 255, 1.0]) and len(few[1]) == 2
    ramp = np.arange(256, dtype=np.uint8)[None, :].repeat(2, axis=0)
    levels, weights = specular_levels(hg.Material(specular_texture=ramp), "o")
    assert len(levels) == 4 and levels[0] == 0.0 and levels[-1] == 1.0
    values = ramp[0] / 255.0
    # the chain B_k = blend(a_k, B_(k-1), P(s_k)) reproduces s itself where the BSDF is linear in s
    s = np.full(values.shape, levels[0])
    for level, weight in zip(levels[1:], weights):
        s = (1 - weight[0]) * s + weight[0] * level
    np.testing.assert_allclose(s, values, atol=1e-6)


def test_config_maps_replace_values_and_an_emission_map_emits():
    material = apply_material_config(hg.Material(emission_texture="a.png", specular_texture="b.png"),
                                     {"specular": 0.2, "emission": [1, 1, 1]})
    assert material.specular_texture is None and material.emission_texture is None
    emitting = {"emission_texture": __file__}  # any existing file: the config only locates it
    assert apply_material_config(hg.Material(), emitting).emission_strength == 1.0
    assert apply_material_config(hg.Material(emission_strength=4.0), emitting).emission_strength == 4.0
