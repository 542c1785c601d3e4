"""Blender's Solidify modifier (``solidify_mode`` EXTRUDE - "Simple" -, its default) on a welded polygon mesh: a
surface becomes a shell of ``thickness`` metres (object frame).

Measured with bpy 4.2 (tests/scene/test_solidify.py): each vertex v with unit vertex normal n (the polygon normals
around it weighted by their corner angles) gives two: v + n t (offset + 1) / 2 on the original polygons and
v + n t (offset - 1) / 2 on a copy of every polygon with its winding reversed; ``offset`` -1 (the default) keeps
the surface where it is and grows the shell behind it (against the normals). With ``use_even_offset`` the
offset is divided by the angle-weighted mean cosine between the vertex normal and its polygons' normals, so
flat faces keep the thickness at corners. ``use_rim`` (default on) closes every boundary edge (an edge of one
polygon) with a quad (b, a, a', b') - a closed shell around an open surface, watertight when the surface is
manifold. ``use_flip_normals`` reverses every polygon. A unit square becomes 8 vertices and 6 quads.
Per-corner attributes are copied (rims take the edge's corners').
"""
from __future__ import annotations

import numpy as np

from .polygon_mesh import PolygonMesh


def _even_scale(mesh: PolygonMesh, normals: np.ndarray) -> np.ndarray:
    """Per vertex: 1 / the corner-angle-weighted mean cosine between its normal and its polygons' normals."""
    angle = mesh.corner_angles()
    facing = np.einsum("ij,ij->i", normals[mesh.corners], mesh.polygon_normals()[mesh.polygon_of_corner()])
    weight = np.bincount(mesh.corners, angle, minlength=len(normals))
    weighted = np.bincount(mesh.corners, angle * facing, minlength=len(normals))
    return np.divide(weight, weighted, out=np.ones(len(normals)), where=weighted > 1e-12)


def solidify(mesh: PolygonMesh, thickness: float, offset: float = -1.0, use_rim: bool = True,
             use_even_offset: bool = False, use_flip_normals: bool = False) -> PolygonMesh:
    """The shell of ``mesh`` (module doc)."""
    normals = mesh.vertex_normals()
    if use_even_offset:
        normals = normals * _even_scale(mesh, normals)[:, None]
    count = len(mesh.positions)
    outer = mesh.positions + normals * (thickness * (offset + 1.0) / 2.0)
    inner = mesh.positions + normals * (thickness * (offset - 1.0) / 2.0)
    # the copy: each polygon's loop reversed (first corner kept first)
    polygon = mesh.polygon_of_corner()
    position_in = np.arange(len(mesh.corners)) - mesh.starts[polygon]
    reversed_order = mesh.starts[polygon] + (-position_in) % mesh.sizes[polygon]
    corners = [mesh.corners, mesh.corners[reversed_order] + count]
    sources = [np.arange(len(mesh.corners)), reversed_order]
    parts = [mesh.part, mesh.part]
    sizes = [mesh.sizes, mesh.sizes]
    if use_rim:
        nxt = mesh.next_corner()
        pairs = np.sort(np.stack([mesh.corners, mesh.corners[nxt]], axis=1), axis=1)
        _, inverse, uses = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
        edge = np.flatnonzero(uses[inverse.reshape(-1)] == 1)  # corners starting a boundary edge
        a, b = mesh.corners[edge], mesh.corners[nxt[edge]]
        corners.append(np.stack([b, a, a + count, b + count], axis=1).ravel())
        sources.append(np.stack([nxt[edge], edge, edge, nxt[edge]], axis=1).ravel())
        parts.append(mesh.part[polygon[edge]])
        sizes.append(np.full(len(edge), 4))
    all_corners, all_sources = np.concatenate(corners), np.concatenate(sources)
    all_sizes = np.concatenate(sizes)
    starts = np.concatenate([[0], np.cumsum(all_sizes)]).astype(np.int64)
    result = PolygonMesh(np.concatenate([outer, inner]), all_corners, starts, np.concatenate(parts),
                         {name: values[all_sources] for name, values in mesh.attributes.items()})
    if use_flip_normals:
        owner = result.polygon_of_corner()
        place = np.arange(len(all_corners)) - starts[owner]
        flipped = starts[owner] + (-place) % all_sizes[owner]
        result = PolygonMesh(result.positions, all_corners[flipped], starts, result.part,
                             {name: values[flipped] for name, values in result.attributes.items()})
    return result
