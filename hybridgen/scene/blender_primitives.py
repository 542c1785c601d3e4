"""Blender 4.2's mesh primitives (``bpy.ops.mesh.primitive_*_add``: what BlenderProc's ``create_primitive`` makes)
as polygon meshes with Blender's UV map: positions (m, object frame, Z up), polygons with Blender's corner order,
per-corner UVs.

Measured with bpy 4.2 (tools/blender_primitives.py; tests/scene/test_blender_primitives.py checks every polygon's
corners and UVs against the stored measurements):

- **cube** (``size``, 2 m): corners (x, y, z) in {-1, 1}^3 x size / 2, x slowest; six quads [0 1 3 2], [2 3 7 6],
  [6 7 5 4], [4 5 1 0], [2 6 4 0], [7 3 1 5]; UVs the cross layout: the first four faces stacked in u 0.375..0.625
  (v from 0 in steps of 0.25), then u 0.125..0.375 and 0.625..0.875 at v 0.5..0.75, each face's corners (u, v),
  (u + 0.25, v), (u + 0.25, v + 0.25), (u, v + 0.25).
- **plane** (``size``, 2 m): corners (-1, -1), (1, -1), (-1, 1), (1, 1) x size / 2, one quad [0 1 3 2], UV
  (x / size + 0.5, y / size + 0.5).
- **cylinder** / **cone** (``vertices`` 32, ``radius`` / ``radius1`` and ``radius2`` (cone: 0), ``depth`` 2 m,
  ``end_fill_type`` NGON, TRIFAN or NOTHING): ring vertex k at angle a_k = 2 pi k / n from +Y towards +X,
  (r sin a_k, r cos a_k), bottom ring at z = -depth / 2, top at +depth / 2. Side quads [b_k, t_k, t_k+1, b_k+1]
  unwrap to u 1 - k / n .. 1 - (k + 1) / n, v 0.5 .. 1 (0 .. 1 without caps); caps and a pointed cone's side
  triangles [b_k, apex, b_k+1] take the circle unwrap: top (0.25, 0.25) + 0.24 (x, y) / r, bottom (0.75, 0.25) +
  0.24 (x, y) / r (without caps one circle at (0.5, 0.5) of radius 0.5). NGON caps: bottom [b_0 .. b_n-1], top
  [t_1, t_0, t_n-1 .. t_2]; the first cap sits after n - 2 side faces (2 for a 3-sided cylinder). TRIFAN: centre vertices first, per k the
  bottom triangle [c_b, b_k, b_k+1], the top one [c_t, t_k+1, t_k], then the side face.
- **UV sphere** (``segments`` 32, ``ring_count`` 16, ``radius`` 1 m): ring i (1 .. R - 1) at polar angle
  pi i / R, segment j at a_j as above; quads [(i, j), (i - 1, j), (i - 1, j + 1), (i, j + 1)], top triangles
  [(1, j), top, (1, j + 1)], bottom ones [bottom, (R - 1, j), (R - 1, j + 1)]; u = 0.5 + atan2(y, x) / 2 pi with
  the seam (the -X half-plane) at 0, a face crossing it lifted by 1, a pole's u that of its face's centre, the whole
  map then shifted so that its smallest u is 0; v = 1 - polar angle / pi.

Blender's faces are flat-shaded. What is not Blender's: the UV sphere's vertex and face order (Blender's follows
from its spin and merge steps; geometry, polygons and UVs are the same).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .polygon_mesh import PolygonMesh

FILL_TYPES = ("NGON", "TRIFAN", "NOTHING")
_CUBE_FACES = [[0, 1, 3, 2], [2, 3, 7, 6], [6, 7, 5, 4], [4, 5, 1, 0], [2, 6, 4, 0], [7, 3, 1, 5]]
_CUBE_UV_ORIGINS = [(0.375, 0.0), (0.375, 0.25), (0.375, 0.5), (0.375, 0.75), (0.125, 0.5), (0.625, 0.5)]
_SQUARE = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])


def _mesh(positions: np.ndarray, polygons: list[list[int]], uvs: np.ndarray) -> PolygonMesh:
    sizes = [len(p) for p in polygons]
    return PolygonMesh(positions=np.asarray(positions, np.float64),
                       corners=np.concatenate([np.asarray(p, np.int64) for p in polygons]),
                       starts=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
                       part=np.zeros(len(polygons), np.int64), attributes={"uvs": np.asarray(uvs, np.float64)})


def cube(size: float = 2.0) -> PolygonMesh:
    """``primitive_cube_add(size=size)``."""
    half = size / 2
    positions = np.array([(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)])
    uvs = np.concatenate([np.array(origin) + 0.25 * _SQUARE for origin in _CUBE_UV_ORIGINS])
    return _mesh(positions, _CUBE_FACES, uvs)


def plane(size: float = 2.0) -> PolygonMesh:
    """``primitive_plane_add(size=size)``."""
    half = size / 2
    positions = np.array([(-half, -half, 0.0), (half, -half, 0.0), (-half, half, 0.0), (half, half, 0.0)])
    return _mesh(positions, [[0, 1, 3, 2]], _SQUARE)


def _ring(count: int, radius: float, z: float) -> np.ndarray:
    angle = 2 * np.pi * np.arange(count) / count
    return np.stack([radius * np.sin(angle), radius * np.cos(angle), np.full(count, z)], axis=1)


def _circle_uv(points: np.ndarray, centre: tuple[float, float], scale: float) -> np.ndarray:
    return np.asarray(centre) + scale * points[:, :2]


def cone(vertices: int = 32, radius1: float = 1.0, radius2: float = 0.0, depth: float = 2.0,
         end_fill_type: str = "NGON") -> PolygonMesh:
    """``primitive_cone_add`` (``radius1`` at the bottom, z = -depth / 2; ``radius2`` 0: a point at the top)."""
    n = int(vertices)
    if n < 3 or end_fill_type not in FILL_TYPES or not radius1 > 0 or radius2 < 0:
        raise InputError(f"a cone needs vertices >= 3, radius1 > 0, radius2 >= 0 and end_fill_type one of "
                         f"{FILL_TYPES}; got {vertices}, {radius1}, {radius2}, {end_fill_type!r}")
    caps = end_fill_type != "NOTHING"
    fan = end_fill_type == "TRIFAN"
    bottom, top = _ring(n, radius1, -depth / 2), _ring(n, radius2, depth / 2)
    uv_radius, top_centre = (0.24, (0.25, 0.25)) if caps else (0.5, (0.5, 0.5))
    bottom_centre = (0.75, 0.25) if caps else (0.5, 0.5)
    pointed = radius2 == 0
    top_scale = uv_radius / (radius2 if not pointed else radius1)
    centres = [np.array([[0.0, 0.0, -depth / 2]]), np.array([[0.0, 0.0, depth / 2]])] if fan else []
    if pointed:  # ring 0..n-1 (after the bottom centre), then the apex
        positions = np.concatenate([*centres[:1], bottom, top[:1]])
        b = np.arange(n) + (1 if fan else 0)
        t = np.full(n, len(positions) - 1)
    else:  # bottom and top vertex of each k in turn (after both centres)
        positions = np.concatenate([*centres, np.stack([bottom, top], axis=1).reshape(-1, 3)])
        b = 2 * np.arange(n) + (2 if fan else 0)
        t = b + 1
    position_uv = {"top": _circle_uv(positions, top_centre, top_scale),
                   "bottom": _circle_uv(positions, bottom_centre, uv_radius / radius1)}
    v_low = 0.5 if caps else 0.0
    polygons: list[list[int]] = []
    uvs: list[np.ndarray] = []

    def side(k: int) -> None:
        k1 = (k + 1) % n
        if pointed:
            polygons.append([b[k], t[k], b[k1]])
            uvs.append(position_uv["top"][[b[k], t[k], b[k1]]])
        else:
            polygons.append([b[k], t[k], t[k1], b[k1]])
            u0, u1 = 1 - k / n, 1 - (k + 1) / n
            uvs.append(np.array([(u0, v_low), (u0, 1.0), (u1, 1.0), (u1, v_low)]))

    def add_cap(corners: list[int], which: str) -> None:
        polygons.append(corners)
        uvs.append(position_uv[which][corners])

    top_cap = [t[1], t[0], *t[:1:-1]]
    for k in range(n):
        if fan:
            add_cap([0, b[k], b[(k + 1) % n]], "bottom")
            if not pointed:
                add_cap([1, t[(k + 1) % n], t[k]], "top")
        elif caps and k == (n - 2 if pointed else max(n - 2, 2)):  # where Blender's dissolved fan lands
            add_cap(list(b) if pointed else top_cap, "bottom" if pointed else "top")
        side(k)
    if caps and not fan and not pointed:
        add_cap(list(b), "bottom")
    return _mesh(positions, polygons, np.concatenate(uvs))


def cylinder(vertices: int = 32, radius: float = 1.0, depth: float = 2.0, end_fill_type: str = "NGON") -> PolygonMesh:
    """``primitive_cylinder_add``: a cone with equal radii."""
    return cone(vertices, radius, radius, depth, end_fill_type)


def _sphere_u(azimuth: np.ndarray | float) -> np.ndarray:
    """Blender's sphere u of points at ``azimuth`` (from +Y towards +X): 0.5 + atan2(y, x) / 2 pi, the seam
    (azimuth 3 pi / 2, atan2 = pi) read as -pi: u = 0 there."""
    on_seam = np.isclose(np.mod(azimuth, 2 * np.pi), 1.5 * np.pi)
    return np.where(on_seam, 0.0, np.mod(0.75 - np.asarray(azimuth) / (2 * np.pi), 1.0))


def uv_sphere(segments: int = 32, ring_count: int = 16, radius: float = 1.0) -> PolygonMesh:
    """``primitive_uv_sphere_add``; vertices: the top pole, rings 1 .. R - 1 (segment by segment), the bottom
    pole."""
    s, r = int(segments), int(ring_count)
    if s < 3 or r < 3 or not radius > 0:
        raise InputError(f"a UV sphere needs segments >= 3, ring_count >= 3 and radius > 0; got {segments}, "
                         f"{ring_count}, {radius}")
    polar = np.pi * np.arange(1, r) / r
    angle = 2 * np.pi * np.arange(s) / s
    rings = np.stack([np.outer(np.sin(polar), np.sin(angle)), np.outer(np.sin(polar), np.cos(angle)),
                      np.repeat(np.cos(polar)[:, None], s, axis=1)], axis=-1) * radius
    positions = np.concatenate([[(0.0, 0.0, radius)], rings.reshape(-1, 3), [(0.0, 0.0, -radius)]])
    top, bottom = 0, len(positions) - 1

    def at(i: int, j: int) -> int:
        return 1 + (i - 1) * s + j % s

    polygons = [[at(1, j), top, at(1, j + 1)] for j in range(s)]
    polygons += [[at(i, j), at(i - 1, j), at(i - 1, j + 1), at(i, j + 1)] for i in range(2, r) for j in range(s)]
    polygons += [[bottom, at(r - 1, j), at(r - 1, j + 1)] for j in range(s)]
    vertex_u = np.concatenate([[np.nan], np.tile(_sphere_u(angle), r - 1), [np.nan]])
    uvs = []
    for polygon in polygons:
        u = vertex_u[polygon]
        if len(polygon) == 3:
            j = (polygon[0] - 1 if polygon[1] == top else polygon[1] - 1) % s
            u = np.where(np.isnan(u), _sphere_u(angle[j] + np.pi / s), u)
        u = np.where(u.max() - u > 0.5, u + 1.0, u)
        z = positions[polygon, 2] / radius
        uvs.append(np.stack([u, 1.0 - np.arccos(np.clip(z, -1.0, 1.0)) / np.pi], axis=1))
    uv = np.concatenate(uvs)
    uv[:, 0] -= uv[:, 0].min()
    return _mesh(positions, polygons, uv)
