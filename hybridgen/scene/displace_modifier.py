"""Blender's Displace modifier on a welded polygon mesh (:class:`~hybridgen.scene.polygon_mesh.PolygonMesh`).

Every vertex moves by ``strength x (t - mid_level)`` - metres in the object's local frame - along ``direction``:
NORMAL, its vertex normal (the polygon normals around it weighted by their corner angles, as Blender's vertex
normals; of the mesh as the modifier receives it, e.g. after a subdivision), or the local X, Y or Z axis. ``t`` is
the texture's value at the vertex's texture coordinate (``texture_coords``): LOCAL, the vertex position itself
(Blender's default) in Blender's mesh frame (``mesh_frame``, a 4x4 from hybridgen's local frame to the coordinates
Blender's mesh holds: identity, or the inverse axis turn of an OBJ that hybridgen's v1 loader turned Z-up); GLOBAL, the position in the world (``local2world`` given); UV, the vertex's UV (u, v, 0)
mapped to 2 u - 1, 2 v - 1 (the last corner's UV where a vertex has several, as Blender takes one). A vertex
shared by several polygons moves once, so the surface does not tear. Textures:
:mod:`hybridgen.scene.displacement_texture` (images, procedural textures).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import InputError
from .polygon_mesh import PolygonMesh

DIRECTIONS = ("NORMAL", "X", "Y", "Z")
TEXTURE_COORDS = ("LOCAL", "GLOBAL", "UV")


def texture_points(mesh: PolygonMesh, texture_coords: str, local2world: np.ndarray | None = None,
                   mesh_frame: np.ndarray | None = None) -> np.ndarray:
    """(V, 3) texture-space points of the vertices (module doc)."""
    if texture_coords == "LOCAL":
        if mesh_frame is None:
            return mesh.positions.copy()
        frame = np.asarray(mesh_frame, dtype=np.float64)
        return mesh.positions @ frame[:3, :3].T + frame[:3, 3]
    if texture_coords == "GLOBAL":
        matrix = np.eye(4) if local2world is None else np.asarray(local2world, dtype=np.float64)
        return mesh.positions @ matrix[:3, :3].T + matrix[:3, 3]
    if "uvs" not in mesh.attributes:
        raise InputError("the Displace modifier's texture_coords UV needs a UV map (add_uv_mapping first)")
    points = np.zeros_like(mesh.positions)
    points[mesh.corners, :2] = 2.0 * mesh.attributes["uvs"][:, :2] - 1.0
    return points


def displace(mesh: PolygonMesh, texture: Callable[[np.ndarray], np.ndarray] | None, strength: float, mid_level: float,
             direction: str = "NORMAL", texture_coords: str = "LOCAL",
             local2world: np.ndarray | None = None, mesh_frame: np.ndarray | None = None) -> PolygonMesh:
    """``mesh`` with its vertices displaced (module doc); ``texture`` maps (V, 3) texture points to (V,) values
    (None: no texture, every vertex reads 1 as in Blender)."""
    if direction not in DIRECTIONS:
        raise InputError(f"the Displace modifier's direction {direction!r} is not supported by hybridgen yet "
                         f"({', '.join(DIRECTIONS)} are)")
    if texture_coords not in TEXTURE_COORDS:
        raise InputError(f"the Displace modifier's texture_coords {texture_coords!r} is not supported by hybridgen "
                         f"yet ({', '.join(TEXTURE_COORDS)} are)")
    if texture is None:
        values = np.ones(len(mesh.positions))
    else:
        values = np.asarray(texture(texture_points(mesh, texture_coords, local2world, mesh_frame)), dtype=np.float64)
    amount = float(strength) * (values - float(mid_level))
    if direction == "NORMAL":
        offset = mesh.vertex_normals() * amount[:, None]
    else:
        offset = np.zeros_like(mesh.positions)
        offset[:, "XYZ".index(direction)] = amount
    return PolygonMesh(mesh.positions + offset, mesh.corners, mesh.starts, mesh.part, mesh.attributes)
