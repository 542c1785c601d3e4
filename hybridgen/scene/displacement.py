"""True geometric displacement: Blender's Subdivision + Displace modifiers (BlenderProc's EntityManipulator
``cf_add_displace_modifier_with_texture``) applied to the scene model's mesh, so color, depth, normals and
every other label see the displaced surface.

The modifier, as Blender applies it:

1. When the mesh has at most ``min_vertices_for_subdiv`` vertices, it is subdivided ``subdiv_level`` times.
   Blender's Subdivision Surface is Catmull-Clark, which also rounds the shape of a coarse mesh (a cube
   becomes a rounded box); hybridgen subdivides linearly (every triangle into four at its edge midpoints,
   UVs, normals and vertex colors interpolated), which keeps the surface where it was - identical to
   Catmull-Clark for flat patches with straight boundaries (planes, floors, walls), not for curved ones.
   ``subdiv_level`` is applied as given; BlenderProc's RgbRenderer caps render subdivision at its
   ``simplify_subdivision_render`` (3 by default), so give at most 3 to match its renders.
2. Every vertex moves along its normal by (h - ``mid_level``) x ``strength`` metres (object units), h the
   height texture's value at the vertex's texture coordinate: ``texture_coords`` "LOCAL" (Blender's default,
   which BlenderProc keeps: local x, y in [-1, 1] span the image once, u = (x + 1) / 2, v = (y + 1) / 2) or
   "UV" (the mesh UVs). The image is sampled bilinearly and repeats, v up (row 0 is the image's top), its
   first channel read as linear data (0..1; 16-bit images keep their precision).
   The normal is the area-weighted normal of the faces around the vertex's position, and vertices that
   share a position (seams of a split mesh) share one normal and one height, so the surface does not tear
   (Blender's mesh has one vertex there).
3. Smooth-shaded meshes get the displaced surface's area-weighted vertex normals; flat-shaded ones stay flat
   (labels then use the displaced triangles' own normals).

Blender's procedural textures (CLOUDS, VORONOI, ... of ``sampler.Texture``) are not reproduced: the
texture here is a height image (path or HxW[xC] array).

Objects sharing one mesh (the same vertex/face/UV/normal arrays: instances of one model) and one modifier
get one displaced mesh, computed once and shared (:func:`displace_objects`), so instancing still holds.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import InputError
from .mesh_object import MeshObject

TEXTURE_COORDS = ("LOCAL", "UV")


@dataclass(frozen=True)
class Displacement:
    """Parameters of the Subdivision + Displace modifiers (BlenderProc's names and defaults)."""

    texture: Any  # height image: file path or HxW[xC] array (uint8/uint16 -> 0..1, float as is)
    strength: float = 0.1
    mid_level: float = 0.5
    subdiv_level: int = 2
    min_vertices_for_subdiv: int = 10000
    texture_coords: str = "LOCAL"

    def check(self, owner: str) -> None:
        """One-line errors for values that cannot displace."""
        if self.texture_coords not in TEXTURE_COORDS:
            raise InputError(f"object '{owner}': displacement texture_coords must be one of {TEXTURE_COORDS}, "
                             f"got {self.texture_coords!r}")
        if not (0 <= self.subdiv_level <= 8):
            raise InputError(f"object '{owner}': displacement subdiv_level must be in 0..8, got {self.subdiv_level}")
        if not (np.isfinite(self.strength) and np.isfinite(self.mid_level)):
            raise InputError(f"object '{owner}': displacement strength and mid_level must be finite")

    def key(self) -> tuple[Any, ...]:
        """Hashable identity (an image array by identity)."""
        texture = ("array", id(self.texture)) if isinstance(self.texture, np.ndarray) else str(self.texture)
        return (texture, self.strength, self.mid_level, self.subdiv_level, self.min_vertices_for_subdiv,
                self.texture_coords)


def height_image(texture: Any, owner: str) -> np.ndarray:
    """HxW float64 heights (first channel, 0..1 for integer images), rows top-down as stored."""
    from ..render.material_textures import data_image

    return data_image(texture, owner, "displacement texture")[..., 0].astype(np.float64)


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Values of ``image`` (HxW, row 0 = top = v 1) at ``uv`` (N x 2), bilinear between texel centres,
    repeating (as Blender's and Mitsuba's image textures)."""
    height, width = image.shape
    x = uv[:, 0] * width - 0.5
    y = (1.0 - uv[:, 1]) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    x0i, y0i = x0.astype(np.int64) % width, y0.astype(np.int64) % height
    x1i, y1i = (x0i + 1) % width, (y0i + 1) % height
    top = image[y0i, x0i] * (1 - fx) + image[y0i, x1i] * fx
    bottom = image[y1i, x0i] * (1 - fx) + image[y1i, x1i] * fx
    return top * (1 - fy) + bottom * fy


def subdivide(faces: np.ndarray, attributes: list[np.ndarray | None],
              levels: int) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """Linear subdivision ``levels`` times: each triangle into four at its edge midpoints (one new vertex per
    edge, shared by both faces of the edge); per-vertex ``attributes`` (positions, UVs, ...) interpolated."""
    for _ in range(levels):
        count = len(attributes[0])  # type: ignore[arg-type]
        edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        mids = (count + inverse.reshape(-1, 3)).astype(np.int64)  # midpoints of edges (a,b), (b,c), (c,a)
        a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
        ab, bc, ca = mids[:, 0], mids[:, 1], mids[:, 2]
        faces = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1),
                          np.stack([ab, bc, ca], 1)], axis=1).reshape(-1, 3)
        attributes = [None if values is None else
                      np.concatenate([values, 0.5 * (values[unique[:, 0]] + values[unique[:, 1]])])
                      for values in attributes]
    return faces, attributes


def _area_weighted_normals(vertices: np.ndarray, faces: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Unit normals per vertex: the summed (area-weighted) normals of the faces around each position group."""
    corners = vertices[faces]
    weighted = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    summed = np.zeros((int(groups.max()) + 1, 3))
    for corner in range(3):
        np.add.at(summed, groups[faces[:, corner]], weighted)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    unit = np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)
    return unit[groups]


def displaced_arrays(obj: MeshObject, modifier: Displacement) -> dict[str, np.ndarray | None]:
    """The displaced mesh of ``obj`` (local frame): vertices, faces, uvs, vertex_normals, vertex_colors."""
    modifier.check(obj.name)
    if modifier.texture_coords == "UV" and obj.uvs is None:
        raise InputError(f"object '{obj.name}' has no UVs for its displacement texture (texture_coords UV)")
    levels = modifier.subdiv_level if len(obj.vertices) <= modifier.min_vertices_for_subdiv else 0
    uvs = None if obj.uvs is None else np.asarray(obj.uvs, np.float64)
    faces, (vertices, uvs, normals, colors) = subdivide(
        obj.faces, [obj.vertices, uvs, obj.vertex_normals, obj.vertex_colors], levels)
    assert vertices is not None
    _, first, groups = np.unique(vertices, axis=0, return_index=True, return_inverse=True)
    groups = groups.reshape(-1)
    coords = uvs if modifier.texture_coords == "UV" else (vertices[:, :2] + 1.0) / 2.0
    assert coords is not None
    heights = sample_bilinear(height_image(modifier.texture, obj.name), coords)[first][groups]
    directions = _area_weighted_normals(vertices, faces, groups)
    moved = vertices + directions * ((heights - modifier.mid_level) * modifier.strength)[:, None]
    if normals is not None:  # smooth shading: the displaced surface's own vertex normals
        normals = _area_weighted_normals(moved, faces, np.unique(moved, axis=0, return_inverse=True)[1].reshape(-1))
    return {"vertices": moved, "faces": faces, "uvs": uvs, "vertex_normals": normals, "vertex_colors": colors}


_CACHED = [name for name, value in vars(MeshObject).items() if isinstance(value, cached_property)]


def displace_objects(objects: list[MeshObject], modifier: Displacement,
                     done: dict[tuple[Any, ...], dict[str, np.ndarray | None]] | None = None) -> None:
    """Replace each object's mesh by its displaced mesh; objects sharing their arrays (and the modifier)
    share the result. ``done`` carries the computed meshes across calls (one dict per manipulator run)."""
    done = {} if done is None else done
    for obj in objects:
        key = (id(obj.vertices), id(obj.faces), id(obj.uvs), id(obj.vertex_normals), id(obj.vertex_colors),
               modifier.key())
        if key not in done:
            done[key] = displaced_arrays(obj, modifier)
        for name, value in done[key].items():
            setattr(obj, name, value)
        for name in _CACHED:
            obj.__dict__.pop(name, None)
        obj.validate()
