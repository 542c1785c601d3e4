"""Infused images over the base color (hybridgen.scene.color_layer; BlenderProc's infuse_texture): Cycles' MixRGB
blends against hand-computed values, and both renderers against an independent NumPy evaluation - the raster albedo
at each pixel centre of an analytically ray-cast square, and the path tracer's base color (the diffuse reflectance
of its BSDF) at random UV points: the base color (value or image) blended with the layers' images read bilinearly,
repeating, at UV / texture scale, inverted on request, nested innermost first."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.render.raster.albedo_pass import AlbedoPass
from hybridgen.render.tonemap import srgb_decode
from hybridgen.scene.color_layer import BLEND_OF_MODE, ColorLayer, apply_layer, blend_channel
from hybridgen.scene.gradient_noise import NUMPY
from tests.render.test_dust_albedo import _hits

SIZE = (128, 96)
BASE = np.array([0.1, 0.7, 0.45])
LAYER_PIXELS = np.array([[[250, 10, 60], [20, 200, 120], [128, 128, 128]],
                         [[0, 0, 255], [255, 255, 0], [90, 30, 200]]], np.uint8)
BASE_PIXELS = np.array([[[200, 40, 10], [10, 90, 220]], [[60, 250, 30], [140, 140, 140]]], np.uint8)


def test_blends_are_cycles_mix_and_overlay() -> None:
    """Cycles' svm_mix_blend and svm_mix_overlay at hand-computed points, and BlenderProc's mode -> blend swap."""
    base, layer = np.array([0.2, 0.6, 0.5]), np.array([0.9, 0.3, 0.1])
    assert np.allclose(blend_channel(NUMPY, "MIX", 0.25, base, layer), 0.75 * base + 0.25 * layer)
    overlay = blend_channel(NUMPY, "OVERLAY", 0.5, base, layer)
    # c1 < 0.5: c1 (1 - f + 2 f c2); else 1 - (1 - f + 2 f (1 - c2)) (1 - c1)
    assert np.allclose(overlay, [0.2 * (0.5 + 0.9), 1 - (0.5 + 0.7) * 0.4, 1 - (0.5 + 0.9) * 0.5])
    assert np.allclose(blend_channel(NUMPY, "OVERLAY", 1.0, base, layer), [2 * 0.2 * 0.9, 1 - 2 * 0.4 * 0.7, 0.1])
    assert np.allclose(blend_channel(NUMPY, "OVERLAY", 0.0, base, layer), base)
    assert BLEND_OF_MODE == {"mix": "OVERLAY", "overlay": "MIX"}  # BlenderProc's substring test
    inverted = apply_layer(NUMPY, ColorLayer("x", "MIX", 1.7, invert=True), tuple(base), tuple(layer))
    assert np.allclose(inverted, 1.0 - layer)  # factor clamped to 1: the inverted image alone


def _bilinear(pixels: np.ndarray, u: np.ndarray, v: np.ndarray, srgb: bool = True) -> np.ndarray:
    """Linear RGB of ``pixels`` (uint8, rows top-down) at Blender UV (v up), bilinear between texel centres,
    repeating - decoded before filtering, as GL's sRGB formats and Mitsuba's bitmaps do."""
    values = pixels[::-1].astype(np.float64) / 255.0
    values = srgb_decode(values) if srgb else values
    h, w = values.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    i0, j0 = x0.astype(int) % w, y0.astype(int) % h
    i1, j1 = (i0 + 1) % w, (j0 + 1) % h
    return ((1 - fy) * ((1 - fx) * values[j0, i0] + fx * values[j0, i1])
            + fy * ((1 - fx) * values[j1, i0] + fx * values[j1, i1]))


def _expected(u: np.ndarray, v: np.ndarray, base: np.ndarray, layers: list[ColorLayer],
              images: dict[str, np.ndarray]) -> np.ndarray:
    rgb = tuple(base[..., c] for c in range(3))
    for layer in layers:
        texel = _bilinear(images[layer.texture], u / layer.texture_scale, v / layer.texture_scale, layer.texture_srgb)
        rgb = apply_layer(NUMPY, layer, rgb, tuple(texel[..., c] for c in range(3)))
    return np.stack(rgb, -1)


@pytest.fixture
def images(tmp_path) -> dict[str, np.ndarray]:
    out = {}
    for name, pixels in (("layer.png", LAYER_PIXELS), ("base.png", BASE_PIXELS)):
        Image.fromarray(pixels).save(tmp_path / name)
        out[str(tmp_path / name)] = pixels
    return out


def _layers(images: dict[str, np.ndarray]) -> list[ColorLayer]:
    layer = next(path for path in images if path.endswith("layer.png"))
    return [ColorLayer(layer, "OVERLAY", 0.6, 0.3), ColorLayer(layer, "MIX", 0.35, 0.7, invert=True),
            ColorLayer(layer, "MIX", 0.5, 0.45, texture_srgb=False)]


def _square(material: hg.Material) -> hg.Scene:
    vertices = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    scene = hg.Scene()
    scene.add(hg.MeshObject(name="square", vertices=vertices, faces=np.array([[0, 1, 2], [0, 2, 3]]),
                            material=material, uvs=np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.2, *SIZE, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.1, -0.4, 2.5], [0.0, 0.0, 0.0]))
    return scene


def _uv_of_pixels(scene: hg.Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, inside) of each pixel centre's ray on the square z = 0 (UV = (xy + 1) / 2)."""
    x, y, _ = _hits(scene)
    return (x + 1) / 2, (y + 1) / 2, (np.abs(x) < 0.98) & (np.abs(y) < 0.98)


@pytest.mark.parametrize("textured", [False, True])
def test_raster_albedo_matches_numpy(gl_context, images: dict[str, np.ndarray], textured: bool) -> None:
    layers = _layers(images)
    base_path = next(path for path in images if path.endswith("base.png"))
    material = hg.Material(base_color=(*BASE, 1.0), base_color_texture=base_path if textured else None,
                           base_color_layers=tuple(layers))
    scene = _square(material)
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    u, v, inside = _uv_of_pixels(scene)
    base = _bilinear(images[base_path], u, v) if textured else np.broadcast_to(BASE, u.shape + (3,))
    expected = _expected(u, v, base, layers, images)
    error = np.abs(albedo[inside] - expected[inside]).max(axis=1)
    assert inside.sum() > 3000 and np.mean(error < 4e-3) > 0.97 and error.max() < 0.03, (
        np.mean(error < 4e-3), error.max())
    assert np.abs(expected[inside] - base[inside]).max() > 0.2  # the layers change the color


def test_plain_object_beside_a_layered_one_keeps_its_color(gl_context, images: dict[str, np.ndarray]) -> None:
    scene = _square(hg.Material(base_color=(*BASE, 1.0), base_color_layers=tuple(_layers(images))))
    plain = hg.MeshObject(name="plain", vertices=np.array([[1.2, -1, 0], [3, -1, 0], [3, 1, 0.0]]),
                          faces=np.array([[0, 1, 2]]), material=hg.Material(base_color=(0.3, 0.2, 0.1, 1.0)))
    scene.add(plain)
    albedo = AlbedoPass(hg.RasterView(scene)).render(hg.look_at([1.0, -0.2, 4.0], [1.0, 0.0, 0.0]),
                                                     background=(0, 0, 0))
    colors = albedo.reshape(-1, 3)
    assert np.sum(np.all(colors == np.float32([0.3, 0.2, 0.1]), axis=1)) > 200


@pytest.mark.parametrize("textured", [False, True])
def test_path_tracer_base_color_matches_numpy(jit_variant: str, images: dict[str, np.ndarray],
                                              textured: bool) -> None:
    """The diffuse reflectance of the material's Mitsuba BSDF (Lambertian here) at random UV points."""
    import drjit as dr
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    mi.set_variant(jit_variant)
    layers = _layers(images)
    base_path = next(path for path in images if path.endswith("base.png"))
    material = hg.Material(base_color=(*BASE, 1.0), specular=0.0, base_color_layers=tuple(layers),
                           base_color_texture=base_path if textured else None)
    bsdf = mi.load_dict(bsdf_dict(material, "square", uvs=True))
    rng = np.random.default_rng(3)
    u, v = rng.uniform(-1.5, 2.5, 4000), rng.uniform(-1.5, 2.5, 4000)
    si = dr.zeros(mi.SurfaceInteraction3f, len(u))
    si.n = si.sh_frame.n = mi.Vector3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(0, 0, 1)
    si.uv = mi.Point2f(mi.Float(u.astype(np.float32)), mi.Float((1.0 - v).astype(np.float32)))  # Mitsuba's flip
    ours = np.stack([np.asarray(c) for c in bsdf.eval_diffuse_reflectance(si)], -1)
    base = _bilinear(images[base_path], u, v) if textured else np.broadcast_to(BASE, u.shape + (3,))
    expected = _expected(u, v, base, layers, images)
    error = np.abs(ours - expected).max(axis=1)
    assert np.mean(error < 1e-3) > 0.99 and error.max() < 5e-3, (np.mean(error < 1e-3), error.max())


def test_missing_layer_image_is_one_line(jit_variant: str, tmp_path) -> None:
    import mitsuba as mi

    from hybridgen.errors import InputError
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    mi.set_variant(jit_variant)
    material = hg.Material(base_color_layers=(ColorLayer(str(tmp_path / "gone.png")),))
    with pytest.raises(InputError, match="gone.png"):
        bsdf_dict(material, "square", uvs=True)
