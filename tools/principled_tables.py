"""Generate the albedo tables of hybridgen's Principled BSDF (hybridgen/render/pathtrace/principled_tables.npz).

The tables are integrated here numerically (float64 NumPy, deterministic stratified quadrature of GGX visible-normal
samples, Heitz 2018), from the definitions of the energy-compensation model Blender 4.2's Principled BSDF uses
(Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks"; Turquin 2019, "Practical multiple
scattering compensation for microfacet models"). Nothing is copied from Cycles: the grids are chosen to match how
Cycles indexes its own tables (so the lookups agree), the values are computed here.

Axes (all grids include both ends; linear interpolation between nodes):

- ``rough``: Blender's Roughness input r in 0..1 (GGX alpha = r^2), 32 nodes (2-D tables) or 16 nodes (3-D).
- ``mu``: cosine of the view direction to the normal, 0..1 (the first node is evaluated at 1e-4).
- ``z``: the IOR axis, z = ((eta - 1) / (eta + 1))^(1/2), i.e. eta = ior_from_F0(z^4); z in 1e-4..0.99.

Tables (dimensionless):

- ``ggx_E[mu, rough]``: directional albedo of single-scattering GGX (height-correlated Smith), Fresnel 1.
- ``ggx_Eavg[rough]``: its cosine-weighted average, 2 int E(mu) mu dmu.
- ``glass_E[z, mu, rough]`` / ``glass_inv_E``: albedo (reflection + refraction) of a rough dielectric interface
  with relative IOR eta (entering) / 1/eta (leaving), dielectric Fresnel, untinted.
- ``glass_Eavg[z, rough]`` / ``glass_inv_Eavg``: their cosine-weighted averages.
- ``schlick_s[z, mu, rough]``: the interpolation factor s with which the Fresnel-weighted albedo of an
  energy-compensated GGX reflection lobe is F0 + (1 - F0) s: the mean over visible normals h of
  (F(h.wi, eta) - F0) / (1 - F0), counting normals whose mirror direction leaves the surface only.
- ``fresnel_avg[z]``: 2 int F(mu, eta) mu dmu, the dielectric Fresnel's cosine-weighted average.

Usage: ``.venv/bin/python tools/principled_tables.py [--samples 128]`` (samples per axis of the stratified
quadrature; 128 -> 16384 per node, about a minute on 2 cores).
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent.parent / "hybridgen" / "render" / "pathtrace" / "principled_tables.npz"


def ior_from_z(z: np.ndarray) -> np.ndarray:
    """Relative IOR of the ``z`` axis: eta with F0 = ((eta - 1) / (eta + 1))^2 = z^4."""
    root = np.sqrt(np.clip(z ** 4, 0.0, 0.99))
    return (1.0 + root) / (1.0 - root)


def fresnel(cos_i: np.ndarray, eta: np.ndarray | float) -> np.ndarray:
    """Unpolarized dielectric Fresnel reflectance for |cos_i| and relative IOR eta (1 at total internal reflection)."""
    c = np.abs(cos_i)
    g2 = eta * eta - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return np.where(g2 > 0, 0.5 * a * a * (1.0 + b * b), 1.0)


def lambda_ggx(alpha: float, cos: np.ndarray) -> np.ndarray:
    """Smith Lambda of isotropic GGX for a direction at cosine ``cos`` to the normal."""
    c2 = np.maximum(cos * cos, 1e-30)
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * np.maximum(1.0 / c2 - 1.0, 0.0)) - 1.0)


def vndf_normals(mu: float, alpha: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Visible GGX normals (n*n stratified midpoints, Heitz 2018) for wi = (sqrt(1 - mu^2), 0, mu); returns
    (wi, h) with h of shape (n*n, 3)."""
    wi = np.array([np.sqrt(max(1.0 - mu * mu, 0.0)), 0.0, mu])
    u1, u2 = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n, indexing="ij")
    u1, u2 = u1.ravel(), u2.ravel()
    v = np.array([alpha * wi[0], alpha * wi[1], wi[2]])
    v /= np.linalg.norm(v)
    t1 = np.array([-v[1], v[0], 0.0]) if v[2] < 0.9999999 else np.array([1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(v, t1)
    r, phi = np.sqrt(u1), 2.0 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1.0 + v[2])
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))
    nh = p1[:, None] * t1 + p2[:, None] * t2 + p3[:, None] * v
    h = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(nh[:, 2], 1e-7)], axis=1)
    return wi, h / np.linalg.norm(h, axis=1, keepdims=True)


def reflection_terms(mu: float, rough: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Per visible normal: cos(h, wi) and the VNDF sample weight G2/G1 of the mirror direction (0 below)."""
    alpha = max(rough, 1e-4) ** 2
    wi, h = vndf_normals(mu, alpha, n)
    cos_hi = h @ wi
    wo_z = 2.0 * cos_hi * h[:, 2] - wi[2]
    li, lo = lambda_ggx(alpha, np.array(wi[2])), lambda_ggx(alpha, wo_z)
    weight = np.where(wo_z > 0, (1.0 + li) / (1.0 + li + lo), 0.0)
    return cos_hi, weight


def glass_albedo(mu: float, rough: float, eta: float, n: int) -> float:
    """Reflection + refraction albedo of a rough dielectric interface (relative IOR eta) seen at cosine mu."""
    alpha = max(rough, 1e-4) ** 2
    wi, h = vndf_normals(mu, alpha, n)
    cos_hi = h @ wi
    f = fresnel(cos_hi, eta)
    li = lambda_ggx(alpha, np.array(wi[2]))
    wr_z = 2.0 * cos_hi * h[:, 2] - wi[2]
    reflect = np.where(wr_z > 0, (1.0 + li) / (1.0 + li + lambda_ggx(alpha, wr_z)), 0.0)
    inv = 1.0 / eta
    cos_t2 = 1.0 - inv * inv * (1.0 - cos_hi ** 2)
    cos_t = -np.sqrt(np.maximum(cos_t2, 0.0))
    wt = (inv * cos_hi + cos_t)[:, None] * h - inv * wi  # refracted direction (into the lower hemisphere)
    refract = np.where((wt[:, 2] < 0) & (cos_t2 > 0),
                       (1.0 + li) / (1.0 + li + lambda_ggx(alpha, wt[:, 2])), 0.0)
    return float(np.mean(f * reflect + (1.0 - f) * refract))


def cosine_average(values_of_mu, n: int = 64) -> float:
    """2 int_0^1 v(mu) mu dmu by Gauss-Legendre quadrature (n nodes)."""
    x, w = np.polynomial.legendre.leggauss(n)
    mu = 0.5 * (x + 1.0)
    return float(np.sum(0.5 * w * 2.0 * mu * np.array([values_of_mu(m) for m in mu])))


def axis(nodes: int, low: float = 1e-4, high: float = 1.0) -> np.ndarray:
    return np.clip(np.arange(nodes) / (nodes - 1), low, high)


def generate(n: int) -> dict[str, np.ndarray]:
    rough32, mu32 = axis(32), axis(32)
    rough16, mu16, z16 = axis(16), axis(16), axis(16, 1e-4, 0.99)
    eta16 = ior_from_z(z16)
    tables: dict[str, np.ndarray] = {}
    tables["ggx_E"] = np.array([[np.mean(reflection_terms(m, r, n)[1]) for r in rough32] for m in mu32])
    tables["ggx_Eavg"] = np.array([cosine_average(lambda m, r=r: np.mean(reflection_terms(m, r, n // 2)[1]), 32)
                                   for r in rough32])
    for name, etas in (("glass", eta16), ("glass_inv", 1.0 / eta16)):
        tables[f"{name}_E"] = np.array([[[glass_albedo(m, r, e, n) for r in rough16] for m in mu16] for e in etas])
        tables[f"{name}_Eavg"] = np.array([[cosine_average(lambda m, r=r, e=e: glass_albedo(m, r, e, n // 2), 24)
                                            for r in rough16] for e in etas])
    s = np.zeros((16, 16, 16))
    for k, eta in enumerate(eta16):
        f0 = ((eta - 1.0) / (eta + 1.0)) ** 2
        for j, m in enumerate(mu16):
            for i, r in enumerate(rough16):
                cos_hi, weight = reflection_terms(m, r, n)
                ratio = np.clip((fresnel(cos_hi, eta) - f0) / (1.0 - f0), 0.0, 1.0)
                s[k, j, i] = np.mean(np.where(weight > 0, ratio, 0.0))
    tables["schlick_s"] = s
    zf = axis(64, 1e-4, 0.99)
    tables["fresnel_avg"] = np.array([cosine_average(lambda m, e=e: float(fresnel(np.array(m), e)), 128)
                                      for e in ior_from_z(zf)])
    return {key: np.clip(value, 0.0, 1.0).astype(np.float32) for key, value in tables.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=128, help="stratified samples per axis and node")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    tables = generate(args.samples)
    np.savez_compressed(args.out, **tables)
    for key, value in tables.items():
        print(f"{key}: shape {value.shape}, range {value.min():.4f}..{value.max():.4f}")


if __name__ == "__main__":
    main()
