"""hybridgen's Principled BSDF with a frame per layer (render/pathtrace/principled_frames.py, principled_layered.py):
Blender 4.2's coat ignores the base's normal map and bends with its own (checked against the single-frame BSDF
turned analytically), sampling / eval / pdf agree and the sampled directions follow the pdf, energy is conserved;
Cycles' valid-reflection lift of a mapped normal; the emission weight under coat and sheen (1 without either, the
coat tint's Beer's-law ratio between channels); Material / config / Mitsuba wiring of ``coat_normal_texture``."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.render.test_principled_bsdf import mi, sphere_grid  # noqa: F401 - mi: the variant fixture

SAMPLES = 1 << 16
TILT = np.array([0.45, -0.25, 0.857])  # a constant tangent-space normal, 31 degrees off the surface's


def _map(mi, normal=TILT):
    """A 2 x 2 raw bitmap holding one tangent-space normal."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    pixels = np.tile((n * 0.5 + 0.5).astype(np.float32), (2, 2, 1))
    return {"type": "bitmap", "bitmap": mi.Bitmap(pixels), "raw": True, "filter_type": "nearest"}


def bsdf(mi, base=(0.0, 0.0, 0.0), **inputs):
    from hybridgen.render.pathtrace.principled_bsdf import PLUGIN_NAME

    for name in ("coat_tint", "sheen_tint", "specular_tint"):
        if name in inputs:
            inputs[name] = mi.ScalarColor3f(inputs[name])
    return mi.load_dict({"type": PLUGIN_NAME, "base_color": {"type": "rgb", "value": list(base)}, **inputs})


def interaction(mi, wi, n: int, frame=None):
    """``n`` lanes at the view ``wi`` (local), geometric normal +z; ``frame``: the shading frame's axes (s, t, n)."""
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f, n)
    if frame is None:
        si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
    else:
        si.sh_frame = mi.Frame3f(*(_vec(mi, axis) for axis in frame))
    si.n = mi.Vector3f(0.0, 0.0, 1.0)
    si.uv = mi.Point2f(0.25, 0.25)
    si.wi = si.sh_frame.to_local(_vec(mi, wi))
    return si


def _vec(mi, v):
    return mi.Vector3f(*(float(x) for x in v))


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _directions(count: int, seed: int = 0) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(count, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.3  # upper hemisphere, away from grazing
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _eval(mi, b, si, wo_world):
    wo = si.sh_frame.to_local(mi.Vector3f(wo_world.T.astype(np.float32)))
    value, pdf = b.eval_pdf(mi.BSDFContext(), si, wo)
    return np.array(value, np.float64).T, np.array(pdf, np.float64)


COAT = dict(specular=0.0, roughness=0.5, coat_weight=1.0, coat_roughness=0.2)


def test_unlinked_coat_normal_ignores_the_base_map_and_its_own_map_turns_it(mi) -> None:
    """A coat over a black base: with a normal map on Normal only it is the coat without any map (Blender 4.2's
    rule, measured with bpy: docs/principled_bsdf.md); with the map on Coat Normal it is that coat in the frame
    turned to the map's normal (the single-frame BSDF on a shading frame built from that normal)."""
    wi = _unit([0.3, 0.2, 0.9])
    wo = _directions(512)
    n = len(wo)
    plain, _ = _eval(mi, bsdf(mi, **COAT), interaction(mi, wi, n), wo)
    base_mapped, _ = _eval(mi, bsdf(mi, **COAT, normal_map=_map(mi)), interaction(mi, wi, n), wo)
    np.testing.assert_allclose(base_mapped, plain, rtol=1e-5, atol=1e-7)
    tilted = _unit(TILT)
    s = _unit(np.array([1.0, 0.0, 0.0]) - tilted * tilted[0])
    turned_frame = (s, np.cross(tilted, s), tilted)
    turned, _ = _eval(mi, bsdf(mi, **COAT), interaction(mi, wi, n, turned_frame), wo)
    keep = wo @ tilted > 0.05  # directions below the turned normal: the single-frame BSDF has no value there
    coat_mapped, _ = _eval(mi, bsdf(mi, **COAT, coat_normal_map=_map(mi)), interaction(mi, wi, n), wo)
    np.testing.assert_allclose(coat_mapped[keep], turned[keep], rtol=1e-4, atol=1e-7)
    assert np.abs(coat_mapped - plain).max() > 0.1 * plain.max()  # the map does move the coat's lobe


LAYERED = [
    dict(base=(0.6, 0.3, 0.2), roughness=0.4, specular=0.5, coat_weight=1.0, coat_roughness=0.15),
    dict(base=(0.2, 0.4, 0.7), roughness=0.5, specular=0.5, coat_weight=0.6, coat_roughness=0.3,
         sheen_weight=1.0, sheen_roughness=0.4, coat_tint=(0.9, 0.7, 0.5)),
    dict(base=(0.9, 0.9, 0.9), roughness=0.3, metallic=0.5, anisotropic=0.6, coat_weight=1.0, coat_roughness=0.1),
    dict(base=(0.8, 0.9, 1.0), roughness=0.3, transmission=1.0, coat_weight=0.8, coat_roughness=0.2),
]
MAPS = [("normal_map",), ("coat_normal_map",), ("normal_map", "coat_normal_map")]


def _layered(mi, inputs, maps):
    tilts = {"normal_map": TILT, "coat_normal_map": [-0.3, 0.35, 0.89]}
    return bsdf(mi, **dict(inputs), **{name: _map(mi, tilts[name]) for name in maps})


def _sampled(mi, b, wi, n=SAMPLES, seed=1):
    u = np.random.default_rng(seed).random((3, n))
    si = interaction(mi, wi, n)
    bs, weight = b.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
    return np.array(bs.wo).T, np.array(weight, np.float64).T, np.array(bs.pdf, np.float64)


@pytest.mark.parametrize("inputs", LAYERED)
@pytest.mark.parametrize("maps", MAPS)
def test_layered_sample_eval_pdf_agree(mi, inputs, maps) -> None:
    b = _layered(mi, inputs, maps)
    wi = _unit([0.5, 0.1, 0.8])
    wo, weights, pdfs = _sampled(mi, b, wi, n=4096)
    value, pdf = _eval(mi, b, interaction(mi, wi, len(wo)), wo)
    valid = pdfs > 0
    assert valid.mean() > 0.7
    np.testing.assert_allclose(pdf[valid], pdfs[valid], rtol=2e-3)
    np.testing.assert_allclose(value[valid] / pdf[valid, None], weights[valid], rtol=2e-3, atol=1e-6)


@pytest.mark.parametrize("inputs", LAYERED[:3])
@pytest.mark.parametrize("maps", MAPS)
def test_layered_sampling_follows_the_pdf_and_keeps_energy(mi, inputs, maps) -> None:
    """Moments of the sampled directions against int g pdf dw, and the furnace: the mean sample weight equals
    int eval dw (by the sphere grid) and never exceeds 1."""
    b = _layered(mi, inputs, maps)
    wi = _unit([0.5, 0.1, 0.8])
    wo, weights, pdfs = _sampled(mi, b, wi, seed=3)
    directions, cell = sphere_grid()
    value, density = _eval(mi, b, interaction(mi, wi, len(directions)), directions)
    ok = pdfs > 0
    for name, g in (("1", lambda d: np.ones(len(d))), ("z", lambda d: d[:, 2]), ("x", lambda d: d[:, 0]),
                    ("y", lambda d: d[:, 1]), ("xz", lambda d: d[:, 0] * d[:, 2])):
        expected = float((g(directions) * density).sum() * cell)
        found = g(wo)[ok].sum() / len(wo)
        assert found == pytest.approx(expected, abs=4.0 * math.sqrt(max(expected - expected ** 2, 1e-4) / len(wo))
                                      + 0.004), name
    by_sampling, by_integration = weights.mean(axis=0), value.sum(axis=0) * cell
    np.testing.assert_allclose(by_sampling, by_integration, atol=4.0 * weights.std(axis=0).max() / math.sqrt(
        len(weights)) + 0.004)
    assert by_integration.max() <= 1.0 + 0.012


def test_mapped_normal_is_lifted_until_the_mirror_direction_clears_the_surface(mi) -> None:
    """Cycles' ensure_valid_specular_reflection: a grazing view's mirror direction about a steep normal would dive
    below the surface; the lifted normal puts it min(0.9 cos, 0.01) above, and a valid one is unchanged."""
    import drjit as dr

    from hybridgen.render.pathtrace.principled_frames import valid_reflection

    ng = mi.Vector3f(0.0, 0.0, 1.0)
    wi = _vec(mi, _unit([0.95, 0.0, 0.2]))
    steep = _vec(mi, _unit([-0.6, 0.1, 0.8]))
    lifted = valid_reflection(ng, wi, steep)
    mirror = 2.0 * dr.dot(lifted, wi) * lifted - wi
    assert float(dr.norm(lifted)[0]) == pytest.approx(1.0, abs=1e-5)
    assert float(mirror.z[0]) == pytest.approx(min(0.9 * 0.2, 0.01), abs=1e-4)
    gentle = _vec(mi, _unit([0.1, 0.05, 1.0]))
    np.testing.assert_allclose(np.array(valid_reflection(ng, wi, gentle)), np.array(gentle), atol=1e-7)


@pytest.mark.parametrize("mu", [0.95, 0.5, 0.2])
def test_emission_weight_under_coat_and_sheen(mi, mu) -> None:
    """1 with neither layer; below 1 and falling towards grazing views under a coat (what its Fresnel reflects);
    a coat tint's channels in the ratio of Beer's law over the view refracted into the coat,
    (tint_g / tint_r)^(1 / cos_t) with cos_t = sqrt(1 - (1 - mu^2) / ior^2), at coat weight 1."""
    wi = _unit([math.sqrt(1.0 - mu * mu), 0.0, mu])
    si = interaction(mi, wi, 1)
    plain = np.array(bsdf(mi, base=(0.5, 0.5, 0.5), roughness=0.5).emission_weight(si)).ravel()
    np.testing.assert_allclose(plain, 1.0)
    coat = np.array(bsdf(mi, **COAT).emission_weight(si)).ravel()
    grazing = np.array(bsdf(mi, **COAT).emission_weight(interaction(mi, _unit([0.99, 0.0, 0.14]), 1))).ravel()
    assert 0.5 < coat[0] < 0.99 and grazing[0] < coat[0] and np.ptp(coat) == 0
    tint, ior = (1.0, 0.7, 0.4), 1.5
    tinted = np.array(bsdf(mi, **COAT, coat_tint=tint, coat_ior=ior).emission_weight(si)).ravel()
    cos_t = math.sqrt(1.0 - (1.0 - mu * mu) / ior ** 2)
    np.testing.assert_allclose(tinted / tinted[0], [(t / tint[0]) ** (1.0 / cos_t) for t in tint], rtol=1e-5)
    np.testing.assert_allclose(tinted[0], coat[0], rtol=1e-6)
    sheen = np.array(bsdf(mi, sheen_weight=1.0, sheen_roughness=0.3).emission_weight(si)).ravel()
    assert 0.3 < sheen[0] < 1.0
    # without the layers (what Cycles leaves at light samples and last vertices): the tint's absorption alone
    bare = np.array(bsdf(mi, **COAT, sheen_weight=1.0).emission_weight(si, True, False)).ravel()
    np.testing.assert_allclose(bare, 1.0)
    absorbed = np.array(bsdf(mi, **COAT, coat_tint=tint, coat_ior=ior).emission_weight(si, True, False)).ravel()
    np.testing.assert_allclose(absorbed, [t ** (1.0 / cos_t) for t in tint], rtol=1e-5)


def test_normal_maps_reach_the_plugin_coat_normal_only_for_coated_materials(mi, tmp_path) -> None:
    """The material's maps go into the plugin (no ``normalmap`` wrapper, Cycles' normal-map rules); without a coat
    the base's map still does and the coat's is unused; a Lambertian material keeps Mitsuba's wrapper."""
    from dataclasses import replace

    from PIL import Image

    from hybridgen.config.material_config import apply_material_config
    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict
    from hybridgen.scene.material import TEXTURE_SLOTS, Material

    path = tmp_path / "coat_normal.png"
    Image.fromarray(np.full((4, 4, 3), (128, 128, 255), np.uint8)).save(path)
    assert "coat_normal_texture" in TEXTURE_SLOTS
    material = apply_material_config(Material(), {"coat_normal_texture": str(path), "normal_texture": str(path),
                                                  "coat_weight": 1.0})
    assert material.coat_normal_texture == str(path) and material.uses_uvs
    coated = bsdf_dict(material, "ball")
    assert coated["type"] != "normalmap" and {"normal_map", "coat_normal_map"} <= set(coated)
    uncoated_material = apply_material_config(material, {"coat_weight": 0.0})
    uncoated = bsdf_dict(uncoated_material, "ball")
    assert uncoated["type"] != "normalmap" and "normal_map" in uncoated and "coat_normal_map" not in uncoated
    coat_map_only = bsdf_dict(replace(uncoated_material, normal_texture=None), "ball")
    assert coat_map_only["type"] != "normalmap" and not {"normal_map", "coat_normal_map"} & set(coat_map_only)
    lambertian = bsdf_dict(apply_material_config(Material(specular=0.0), {"normal_texture": str(path)}), "ball")
    assert lambertian["type"] == "twosided" and lambertian["material"]["type"] == "normalmap"
