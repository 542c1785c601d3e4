"""A ground tile as Blender evaluates BlenderProc's Rock Essentials ground (a subdivided plane under a Displace and
a Subdivision Surface modifier), rebuilt whenever a later step changes the displacement.

Blender's steps, each measured with bpy 4.2 where it matters:

1. A 2 m plane (``primitive_plane_add``, centred on the origin, Z up, UVs 0..1) scaled by ``plane_scale`` and
   cut ``cuts`` times along each edge (``mesh.subdivide``): an (cuts + 2) x (cuts + 2) vertex grid, the scale
   then applied to the vertices (metres, object frame).
2. Displace along the vertex normal (+Z): (h - 0.5) x ``strength`` metres, h the displacement image at the
   vertex's UV (``texture_coords`` UV; the UVs multiplied by ``uv_scaling``), bilinear and repeating
   (:func:`hybridgen.scene.displacement_texture.sample_bilinear`; Blender's values at a 4 x 4 image agree). A tile
   without an image reads h = 0: the whole tile moves down by strength / 2 (bpy 4.2: z = -0.5 at strength 1).
3. Subdivision Surface at ``levels`` (its render level, capped at 3 as BlenderProc's renderer caps it):
   Catmull-Clark (:mod:`hybridgen.scene.catmull_clark`: Blender's positions within 1e-5 on +-0.25 bumps, the
   tile's corners included); UVs follow the grid linearly (Blender's "keep boundaries" UV
   smoothing keeps a grid's UVs linear). The tile stays flat-shaded, as the plane is.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from . import catmull_clark
from .displacement_texture import height_image, sample_bilinear
from .polygon_mesh import PolygonMesh

SIMPLIFY_SUBDIVISION_RENDER = 3
"""BlenderProc's renderer caps every Subdivision Surface at 3 levels."""


@dataclass
class GroundTile:
    """The tile's modifier stack (module doc); :meth:`mesh` evaluates it."""

    plane_scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    cuts: int = 50
    levels: int = 3
    strength: float = 1.0
    mid_level: float = 0.5
    uv_scaling: float = 1.0
    height: Any = None  # displacement image (path or HxW[xC] array), None: no image (h = 0)

    def control_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The cut plane's (N, N, 3) vertices (metres, scale applied) and (N, N, 2) UVs, N = cuts + 2, rows
        along +Y and columns along +X."""
        n = int(self.cuts) + 2
        t = np.linspace(0.0, 1.0, n)
        v, u = np.meshgrid(t, t, indexing="ij")
        sx, sy, _ = self.plane_scale
        points = np.stack([(2.0 * u - 1.0) * sx, (2.0 * v - 1.0) * sy, np.zeros_like(u)], axis=-1)
        return points, np.stack([u, v], axis=-1) * float(self.uv_scaling)

    def mesh(self, owner: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(V, 3) vertices, (F, 3) faces and (V, 2) UVs of the evaluated tile (module doc)."""
        points, uvs = self.control_grid()
        n = points.shape[0]
        if self.height is None:
            h = np.zeros((n, n))
        else:
            h = sample_bilinear(height_image(self.height, owner), uvs.reshape(-1, 2)).reshape(n, n)
        points[..., 2] = (h - self.mid_level) * float(self.strength)
        quads = grid_quads(n, n)
        mesh = PolygonMesh(positions=points.reshape(-1, 3), corners=quads.ravel(),
                           starts=np.arange(0, quads.size + 1, 4), part=np.zeros(len(quads), np.int64),
                           attributes={"uvs": uvs.reshape(-1, 2)[quads.ravel()]})
        mesh = catmull_clark.subdivide(mesh, min(int(self.levels), SIMPLIFY_SUBDIVISION_RENDER))
        triangles, _ = mesh.fan_triangles()
        vertex_uvs = np.zeros((len(mesh.positions), 2))
        vertex_uvs[mesh.corners] = mesh.attributes["uvs"]  # a grid has one UV per vertex
        return mesh.positions, mesh.corners[triangles], vertex_uvs


def grid_quads(rows: int, cols: int) -> np.ndarray:
    """(Q, 4) vertex indices of a row-major grid's cells, counter-clockwise seen from +Z (rows along +Y, columns
    along +X)."""
    index = np.arange(rows * cols).reshape(rows, cols)
    return np.stack([index[:-1, :-1], index[:-1, 1:], index[1:, 1:], index[1:, :-1]], axis=-1).reshape(-1, 4)
