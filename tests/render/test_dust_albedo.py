"""Dust films in the raster albedo (the ``diffuse`` output and the denoiser's guide; render/raster/albedo_dust.py and
shaders/dust.glsl): at each pixel centre the albedo is (1 - w) base + w dust with w hybridgen.scene.dust's weight
at that point (the NumPy code, evaluated here from an analytic ray cast) - for a noise layer, a texture layer
(sRGB decoded, overlaid per channel, luminance) and a square wound downward seen from above; an object without
dust beside a dusty one keeps its base color exactly."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.render.raster.albedo_pass import AlbedoPass
from hybridgen.scene.dust import DUST_COLOR, LUMINANCE, Dust, dust_weight, overlay, surface_factor
from hybridgen.scene.gradient_noise import NUMPY

BASE = np.array([0.1, 0.2, 0.6])
SIZE = (128, 96)


def _square(x: float, material: hg.Material, down: bool = False) -> hg.MeshObject:
    vertices = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]) + [x, 0, 0]
    faces = np.array([[0, 2, 1], [0, 3, 2]]) if down else np.array([[0, 1, 2], [0, 2, 3]])
    return hg.MeshObject(name=f"square{x}", vertices=vertices, faces=faces, material=material,
                         uvs=np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]))


def _scene(*objects: hg.MeshObject) -> hg.Scene:
    scene = hg.Scene()
    for obj in objects:
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.6, *SIZE, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([2.0, -0.6, 3.5], [2.0, 0.0, 0.0]))
    return scene


def _hits(scene: hg.Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(world x, world y, |cos| to the camera) of each pixel centre's ray on the plane z = 0."""
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    v, u = np.mgrid[0:intr.height, 0:intr.width].astype(np.float64)
    rays = np.stack([u, v, np.ones_like(u)], -1) @ np.linalg.inv(intr.K).T @ pose[:3, :3].T
    rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
    t = -pose[2, 3] / rays[..., 2]
    return pose[0, 3] + t * rays[..., 0], pose[1, 3] + t * rays[..., 1], -rays[..., 2]


def _material(*layers: Dust) -> hg.Material:
    return hg.Material(base_color=(*BASE, 1.0), dust=layers)


def _compare(albedo: np.ndarray, expected: np.ndarray, inside: np.ndarray) -> None:
    error = np.abs(albedo[inside] - expected[inside]).max(axis=1)
    assert inside.sum() > 500 and np.mean(error < 2e-3) > 0.98 and error.max() < 0.02, (
        np.mean(error < 2e-3), error.max())


def test_noise_layers_and_a_plain_neighbour(gl_context) -> None:
    layer = Dust(0.8, texture_scale=5.0)
    scene = _scene(_square(0.0, _material(layer)), _square(2.0, _material()), _square(4.0, _material(layer), True))
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    x, y, cosine = _hits(scene)
    for offset in (0.0, 4.0):  # the square wound downward shows dust from above, as in Cycles
        inside = (np.abs(x - offset) < 0.98) & (np.abs(y) < 0.98)
        f32 = [np.float32(a) for a in ((x - offset + 1) / 2, (y + 1) / 2, np.ones_like(x), cosine)]
        w = dust_weight(*f32, layer)[..., None]
        _compare(albedo, (1 - w) * BASE + w * np.asarray(DUST_COLOR), inside)
        assert w[inside].std() > 0.1  # flakes, not a film
    plain = (np.abs(x - 2.0) < 0.98) & (np.abs(y) < 0.98)
    assert plain.sum() > 100 and np.all(albedo[plain] == np.float32(BASE))


def test_texture_layer(gl_context, tmp_path) -> None:
    Image.new("RGB", (4, 4), (180, 40, 90)).save(tmp_path / "dust.png")
    layer = Dust(1.3, 0.5, str(tmp_path / "dust.png"), True, color=(0.9, 0.9, 0.9))
    scene = _scene(_square(2.0, _material(layer)))
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    x, y, cosine = _hits(scene)
    encoded = np.array([180, 40, 90]) / 255.0
    texel = np.where(encoded <= 0.04045, encoded / 12.92, ((encoded + 0.055) / 1.055) ** 2.4)
    g = surface_factor(NUMPY, np.ones_like(x), cosine)
    gray = sum(weight * overlay(NUMPY, g, channel) for weight, channel in zip(LUMINANCE, texel))
    w = np.clip(1.3 * gray, 0.0, 1.0)[..., None]
    inside = (np.abs(x - 2.0) < 0.98) & (np.abs(y) < 0.98)
    assert 0.2 < w[inside].min() < w[inside].max() < 1.0
    _compare(albedo, (1 - w) * BASE + w * 0.9, inside)


@pytest.mark.parametrize("strength", [0.0, -1.0])
def test_inactive_layers_draw_the_base(gl_context, strength: float) -> None:
    scene = _scene(_square(2.0, _material(Dust(strength))))
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    x, y, _ = _hits(scene)
    inside = (np.abs(x - 2.0) < 0.98) & (np.abs(y) < 0.98)
    assert np.all(albedo[inside] == np.float32(BASE))
