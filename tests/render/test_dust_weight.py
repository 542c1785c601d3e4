"""The dust weight (hybridgen.scene.dust; BlenderProc's add_dust) against Cycles and its analytic form: Cycles' exact
per-sample weights of BlenderProc's own node group (tests/render/data/dust_cycles.json, stored by
tools/dust_vs_cycles.py with bpy 4.2) reproduced by the NumPy weight and by the path tracer's BSDF at the same
points; up-facing surfaces seen head-on get strength on flakes and (2 x 0.8^2.2 - 1) x strength between them,
vertical and downward ones none; Blender's noise is 0 on lattice points and stays in its range."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from hybridgen.scene.dust import Dust, dust_weight, noise_pattern
from hybridgen.scene.gradient_noise import NUMPY, noise_texture, perlin

TABLE = Path(__file__).parent / "data" / "dust_cycles.json"
G_UP = 0.8 ** 2.2  # surface factor of an up-facing surface seen head-on


def _table() -> dict[str, np.ndarray]:
    stored = json.loads(TABLE.read_text())
    return {key: np.asarray(value, np.float64) for key, value in stored.items() if key != "about"}


def _facing(table: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(world z of the viewer-facing normal, |cos| between view and normal) per stored point."""
    dot = (table["view"] * table["normal"]).sum(1)
    return -np.sign(dot) * table["normal"][:, 2], np.abs(dot)


def _numpy_weights(table: dict[str, np.ndarray]) -> np.ndarray:
    normal_z, cosine = _facing(table)
    out = np.empty(len(table["w"]))
    for strength, scale in {(s, t) for s, t in zip(table["strength"], table["scale"])}:
        pick = (table["strength"] == strength) & (table["scale"] == scale)
        f32 = [np.asarray(a[pick], np.float32) for a in (table["uv"][:, 0], table["uv"][:, 1], normal_z, cosine)]
        out[pick] = dust_weight(*f32, Dust(float(strength), float(scale)))
    return out


def test_numpy_weight_matches_cycles() -> None:
    table = _table()
    assert len(table["w"]) == 600 and set(table["strength"]) == {0.0, 0.5, 1.0}
    ours = _numpy_weights(table)
    error = np.abs(ours - table["w"])
    # float32 noise at coordinates up to 5000 and Cycles' own rounding: most points agree to the last bits
    assert np.median(error) < 1e-5 and np.mean(error < 1e-3) > 0.97 and error.max() < 0.02, (
        np.median(error), np.mean(error < 1e-3), error.max())
    dusty = table["w"] > 0.2
    assert dusty.sum() > 100 and (table["w"] == 0).sum() > 100  # the table holds both


def test_path_tracer_weight_matches_cycles(jit_variant: str) -> None:
    """The BSDF's weight (black base, white dust: its diffuse reflectance is the weight) at each stored point,
    from Mitsuba surface interactions built as a ray cast gives them (v flipped, normals in world axes)."""
    import drjit as dr
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict
    from hybridgen.scene.material import Material

    mi.set_variant(jit_variant)
    table = _table()
    out = np.empty(len(table["w"]))
    for strength, scale in {(s, t) for s, t in zip(table["strength"], table["scale"])}:
        pick = np.flatnonzero((table["strength"] == strength) & (table["scale"] == scale))
        material = Material(base_color=(0, 0, 0, 1), specular=0.0, dust=(Dust(strength, scale, color=(1, 1, 1)),))
        bsdf = mi.load_dict(bsdf_dict(material, "table", uvs=True))
        si = dr.zeros(mi.SurfaceInteraction3f, len(pick))
        normal = mi.Vector3f(*[mi.Float(table["normal"][pick, i].astype(np.float32)) for i in range(3)])
        si.n, si.sh_frame = normal, mi.Frame3f(normal)
        view = mi.Vector3f(*[mi.Float(table["view"][pick, i].astype(np.float32)) for i in range(3)])
        si.wi = si.sh_frame.to_local(-view)
        si.uv = mi.Point2f(mi.Float(table["uv"][pick, 0].astype(np.float32)),
                           mi.Float(1.0 - table["uv"][pick, 1].astype(np.float32)))
        out[pick] = np.asarray(bsdf.eval_diffuse_reflectance(si).x)
    error = np.abs(out - table["w"])
    assert np.mean(error < 1e-3) > 0.97 and error.max() < 0.02, (np.mean(error < 1e-3), error.max())


def test_weight_analytic_limits() -> None:
    rng = np.random.default_rng(1)
    u, v = rng.random((2, 20000)).astype(np.float32)
    ones, zeros = np.ones_like(u), np.zeros_like(u)
    pattern = noise_pattern(NUMPY, u, v, 0.1)
    flakes, bare = pattern == 1.0, pattern == 0.0
    assert flakes.mean() > 0.1 and bare.mean() > 0.3  # both kinds of point are common
    for strength in (0.3, 0.5, 1.0, 2.0):
        up = dust_weight(u, v, ones, ones, Dust(strength))
        np.testing.assert_allclose(up[flakes], min(strength, 1.0), rtol=1e-5)
        np.testing.assert_allclose(up[bare], min(strength * (2 * G_UP - 1), 1.0), rtol=1e-4)
        assert np.all((up >= min(strength * (2 * G_UP - 1), 1.0) - 1e-6) & (up <= min(strength, 1.0) + 1e-6))
        # seen from below the viewer-facing normal points down: no up component, no dust head-on
        assert np.all(dust_weight(u, v, -ones, ones, Dust(strength)) == 0.0)
        assert np.all(dust_weight(u, v, zeros, ones, Dust(strength)) == 0.0)  # a wall seen head-on
        # a wall seen at grazing angles: only the facing rim, 2 x 0.2^2.2 x strength at most
        rim = dust_weight(u, v, zeros, 0.0 * ones, Dust(strength))
        np.testing.assert_allclose(rim.max(), min(2 * 0.2 ** 2.2 * strength, 1.0), rtol=1e-5)
    assert np.all(dust_weight(u, v, ones, ones, Dust(0.0)) == 0.0)
    assert np.all(dust_weight(u, v, ones, ones, Dust(-1.0)) == 0.0)


def test_tilted_surfaces_get_less_dust() -> None:
    rng = np.random.default_rng(2)
    u, v = rng.random((2, 20000)).astype(np.float32)
    means = [float(dust_weight(u, v, np.full_like(u, math.cos(a)), np.ones_like(u), Dust(1.0)).mean())
             for a in np.radians([0, 30, 60, 80])]
    assert means == sorted(means, reverse=True) and means[-1] < 0.05 < 0.4 < means[0]


def test_noise_lattice_and_range() -> None:
    grid = np.arange(-3, 4, dtype=np.float32)
    x, y, z = np.meshgrid(grid, grid, grid)
    assert np.all(perlin(NUMPY, x, y, z) == 0.0)  # gradient noise vanishes on the lattice
    rng = np.random.default_rng(3)
    points = (rng.random((3, 50000)) * 40 - 20).astype(np.float32)
    value = noise_texture(NUMPY, *points, scale=1.0, detail=0.0, roughness=0.0, distortion=0.0)
    assert value.min() >= 0.0 and value.max() <= 1.0 and abs(value.mean() - 0.5) < 0.01
    assert 0.1 < value.std() < 0.2  # 0.5 x Blender's signed noise, whose spread is about 0.27
    # cells of 1 / scale: the same pattern at scale 2 reads the points at twice the coordinates
    np.testing.assert_allclose(noise_texture(NUMPY, *points, scale=2.0, detail=0.0, roughness=0.0),
                               noise_texture(NUMPY, *(2 * points), scale=1.0, detail=0.0, roughness=0.0), atol=1e-6)


@pytest.mark.parametrize("scale", [0.0, 1e-3])
def test_degenerate_texture_scales_stay_finite(scale: float) -> None:
    u = np.linspace(0, 1, 100, dtype=np.float32)
    weight = dust_weight(u, u, np.ones_like(u), np.ones_like(u), Dust(1.0, scale))
    assert np.all(np.isfinite(weight)) and np.all((weight >= 0) & (weight <= 1))
