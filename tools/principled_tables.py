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
- ``sheen_a[mu, rough]``, ``sheen_b``, ``sheen_R``: Blender 4.2's sheen lobe (Zeltner, Burley & Chiang 2022,
  a linearly transformed cosine): BSDF x cosine = R D(wo) with D the cosine lobe transformed by the inverse
  matrix [[a, 0, b], [0, a, 0], [0, 0, 1]] in the sheen frame (x: the view direction projected on the surface,
  z: the normal), i.e. D = z a^2 / (pi ((a x + b z)^2 + a^2 y^2 + z^2)^2), and R the lobe's albedo. Axes: mu
  and Sheen Roughness, 65 nodes each (i / 64). Fitted here (:func:`fit_sheen`) to Cycles' own lobe measured by
  tools/principled_sheen_cycles.py (``--sheen MEASUREMENTS.npz``) on a lattice twice as fine: at each measured
  point R is the furnace albedo and (a, b) the least-squares LTC through the lobe's values for 256 light
  directions; each table is then the least-squares bilinear fit of those points. Without ``--sheen`` the stored
  sheen tables are kept as they are.

Usage: ``.venv/bin/python tools/principled_tables.py [--samples 128] [--sheen MEASUREMENTS.npz]`` (samples per
axis of the stratified quadrature; 128 -> 16384 per node, about a minute on 2 cores).
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


SHEEN_KEYS = ("sheen_a", "sheen_b", "sheen_R")


def sheen_quad_frame(mu: np.ndarray) -> np.ndarray:
    """The sheen frames (N, 3 axes, 3) of tools/principled_sheen_cycles.py's quads in world axes: rows x (the
    view direction +Z projected on the quad), y = z cross x, z (the normal, tilted from +Z towards -Y by
    acos(mu))."""
    sin = np.sqrt(1.0 - mu * mu)
    normal = np.stack([np.zeros_like(mu), -sin, mu], axis=1)
    tangent = np.stack([np.zeros_like(mu), mu, sin], axis=1)
    return np.stack([tangent, np.cross(normal, tangent), normal], axis=1)


def sheen_frame_lights(mu: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """World ``directions`` (L, 3) in the sheen frame of each quad of view cosine ``mu`` (N,): (L, N, 3)."""
    return np.einsum("nij,lj->lni", sheen_quad_frame(mu), directions)


def sheen_lobe(a: np.ndarray, b: np.ndarray, light: np.ndarray) -> np.ndarray:
    """The normalized LTC lobe D (sr^-1 x cosine) at local directions ``light`` (..., 3)."""
    x, y, z = light[..., 0], light[..., 1], light[..., 2]
    length2 = np.square(a * x + b * z) + np.square(a * y) + z * z
    return np.where(z > 0, z * np.square(a / np.maximum(length2, 1e-30)) / np.pi, 0.0)


def fit_ltc(light: np.ndarray, value: np.ndarray, albedo: float,
            start: tuple[float, float] | None = None) -> tuple[float, float]:
    """(a, b) of the LTC lobe whose ``albedo`` x D best fits ``value`` at ``light`` (relative least squares;
    from ``start`` when it fits to 1e-4 of the peak, else the best of several starts)."""
    from scipy.optimize import least_squares

    up = light[:, 2] > 0
    light, value = light[up], value[up]
    scale = max(float(value.max()), 1e-20)

    def solve(a0: float, b0: float) -> object:
        return least_squares(lambda p: (albedo * sheen_lobe(p[0], p[1], light) - value) / scale, [a0, b0],
                             bounds=([1e-5, -50.0], [100.0, 50.0]))

    best = solve(*start) if start is not None else None
    if best is None or np.abs(best.fun).max() > 1e-4:
        for a0 in (0.03, 0.3, 1.0, 3.0):
            for b0 in (-1.0, 0.0, 1.0):
                result = solve(a0, b0)
                if best is None or result.cost < best.cost:
                    best = result
    return float(best.x[0]), float(best.x[1])


def bilinear_fit(mu: np.ndarray, rough: np.ndarray, values: np.ndarray, weights: np.ndarray,
                 nodes: int) -> np.ndarray:
    """The ``nodes`` x ``nodes`` table [mu, rough] whose bilinear interpolation (the BSDF's lookup) best fits
    ``values`` at the points (``mu``, ``rough``) in weighted least squares."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.linalg import lsqr

    rows, columns, entries = [], [], []
    fy, fx = mu * (nodes - 1), rough * (nodes - 1)
    y0, x0 = np.minimum(np.floor(fy), nodes - 2).astype(int), np.minimum(np.floor(fx), nodes - 2).astype(int)
    ty, tx = fy - y0, fx - x0
    for dy, wy in ((0, 1.0 - ty), (1, ty)):
        for dx, wx in ((0, 1.0 - tx), (1, tx)):
            rows.append(np.arange(mu.size))
            columns.append((y0 + dy) * nodes + x0 + dx)
            entries.append(wy * wx * weights)
    matrix = coo_matrix((np.concatenate(entries), (np.concatenate(rows), np.concatenate(columns))),
                        shape=(mu.size, nodes * nodes)).tocsr()
    return lsqr(matrix, values * weights, atol=1e-12, btol=1e-12, iter_lim=100000)[0].reshape(nodes, nodes)


SHEEN_NODES = 65
"""Nodes per axis of the sheen tables (mu and Sheen Roughness, i / 64)."""


def fit_sheen(path: Path) -> dict[str, np.ndarray]:
    """The sheen tables (``sheen_a``, ``sheen_b``, ``sheen_R``, [mu, rough], :data:`SHEEN_NODES` squared) fitted
    to Cycles' measurements in ``path`` (tools/principled_sheen_cycles.py's output; its lattice quads, role 0):
    per measured point R is the furnace albedo and (a, b) the LTC through the lobe's values (:func:`fit_ltc`);
    each table is the least-squares bilinear fit of those points (:func:`bilinear_fit`), a and b weighted by
    the albedo (they shape a lobe of that weight)."""
    data = np.load(path)
    grid = data["role"] == 0
    mu, rough = data["mu"][grid].astype(np.float64), data["rough"][grid].astype(np.float64)
    albedo, value = data["albedo"][grid].astype(np.float64), data["value"][:, grid].astype(np.float64)
    light = sheen_frame_lights(mu, data["directions"].astype(np.float64))
    fits, start = np.zeros((mu.size, 2)), None
    for k in range(mu.size):  # row by row along roughness: each fit starts from its neighbour's
        start = fit_ltc(light[:, k], value[:, k], albedo[k], start if k and mu[k] == mu[k - 1] else None)
        fits[k] = start
    weights = albedo + 1e-4
    tables = {"sheen_a": np.maximum(bilinear_fit(mu, rough, fits[:, 0], weights, SHEEN_NODES), 1e-5),
              "sheen_b": bilinear_fit(mu, rough, fits[:, 1], weights, SHEEN_NODES),
              "sheen_R": np.clip(bilinear_fit(mu, rough, albedo, np.ones_like(albedo), SHEEN_NODES), 0.0, 1.0)}
    return {key: value.astype(np.float32) for key, value in tables.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=128, help="stratified samples per axis and node")
    parser.add_argument("--sheen", type=Path, help="refit the sheen tables to these Cycles measurements "
                        "(tools/principled_sheen_cycles.py) and keep every other table as stored")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    with np.load(OUT) as stored:
        tables = {key: stored[key] for key in stored.files}
    if args.sheen is not None:
        tables.update(fit_sheen(args.sheen))
    else:
        tables.update(generate(args.samples))
    np.savez_compressed(args.out, **tables)
    for key, value in tables.items():
        print(f"{key}: shape {value.shape}, range {value.min():.4f}..{value.max():.4f}")


if __name__ == "__main__":
    main()
