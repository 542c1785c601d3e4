"""A mesh as Blender holds one for its modifiers: one vertex per position (welded), polygons as corner loops, and
per-corner ("face-varying") attributes - built from hybridgen's triangle parts and turned back into them.

hybridgen's meshes (:class:`~hybridgen.scene.mesh_object.MeshObject`) are triangles whose vertices are split where
texture coordinates, normals or materials differ; a Blender object is one mesh whose vertices are shared by all
its faces, materials included. :func:`from_parts` welds the parts' vertices by exact position (frames: the
object's local frame, metres), keeps each corner's UV, normal and color, and - where ``polygons`` - merges the
triangles a loader made of one polygon back into it (:mod:`hybridgen.scene.polygon_recovery`).
:meth:`PolygonMesh.to_parts` splits the mesh back into one part per material, triangulating polygons as fans.
"""
from __future__ import annotations

import copy
import os
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .mesh_object import MeshObject

ATTRIBUTES = ("uvs", "vertex_normals", "vertex_colors")
"""The per-vertex arrays of a part that become per-corner attributes."""


@dataclass
class PolygonMesh:
    """Welded positions (V, 3); polygon ``p`` is ``corners[starts[p]:starts[p + 1]]`` (vertex indices in winding
    order); ``part`` (P,) the hybridgen part (material) of each polygon; ``attributes`` per corner (L, k) arrays
    keyed as :data:`ATTRIBUTES` (absent when a part lacks them)."""

    positions: np.ndarray
    corners: np.ndarray
    starts: np.ndarray
    part: np.ndarray
    attributes: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def sizes(self) -> np.ndarray:
        """(P,) corners per polygon."""
        return np.diff(self.starts)

    def polygon_of_corner(self) -> np.ndarray:
        """(L,) the polygon of each corner."""
        return np.repeat(np.arange(len(self.starts) - 1), self.sizes)

    def next_corner(self) -> np.ndarray:
        """(L,) the next corner of the same polygon (wrapping)."""
        following = np.arange(1, len(self.corners) + 1)
        following[self.starts[1:] - 1] = self.starts[:-1]
        return following

    def previous_corner(self) -> np.ndarray:
        """(L,) the previous corner of the same polygon (wrapping)."""
        before = np.arange(-1, len(self.corners) - 1)
        before[self.starts[:-1]] = self.starts[1:] - 1
        return before

    def polygon_normals(self) -> np.ndarray:
        """(P, 3) unit normals by Newell's method (the sum of the loop's edge cross products), zero when
        degenerate."""
        here, after = self.positions[self.corners], self.positions[self.corners[self.next_corner()]]
        summed = np.zeros((len(self.starts) - 1, 3))
        np.add.at(summed, self.polygon_of_corner(), np.cross(here, after))
        length = np.linalg.norm(summed, axis=1, keepdims=True)
        return np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)

    def corner_angles(self) -> np.ndarray:
        """(L,) the polygon's interior angle (radians) at each corner, between its two edges there."""
        here = self.positions[self.corners]
        to_next = self.positions[self.corners[self.next_corner()]] - here
        to_previous = self.positions[self.corners[self.previous_corner()]] - here
        lengths = np.linalg.norm(to_next, axis=1) * np.linalg.norm(to_previous, axis=1)
        cosine = np.divide(np.einsum("ij,ij->i", to_next, to_previous), lengths, out=np.ones(len(here)),
                           where=lengths > 0)
        return np.arccos(np.clip(cosine, -1.0, 1.0))

    def vertex_normals(self) -> np.ndarray:
        """(V, 3) unit vertex normals: the polygon normals weighted by the polygon's corner angle at the vertex
        (Blender's vertex normals); zero for vertices of no polygon."""
        summed = np.zeros_like(self.positions)
        weighted = self.polygon_normals()[self.polygon_of_corner()] * self.corner_angles()[:, None]
        np.add.at(summed, self.corners, weighted)
        length = np.linalg.norm(summed, axis=1, keepdims=True)
        return np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)

    def fan_triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """Corner-index triangles (T, 3) of every polygon as a fan from its first corner, and each one's
        polygon (T,)."""
        sizes = self.sizes
        polygon = np.repeat(np.arange(len(sizes)), np.maximum(sizes - 2, 0))
        step = np.arange(len(polygon)) - np.repeat(np.cumsum(np.maximum(sizes - 2, 0)) - np.maximum(sizes - 2, 0),
                                                  np.maximum(sizes - 2, 0))
        first = self.starts[polygon]
        return np.stack([first, first + step + 1, first + step + 2], axis=1), polygon

    def to_parts(self, templates: list[MeshObject], smooth_normals: bool = True) -> list[MeshObject | None]:
        """One hybridgen part per template (same material, name, attributes), holding this mesh's polygons of
        that part, triangulated; corners with equal vertex and attributes share a vertex. Parts that had vertex
        normals (smooth shading) get this mesh's :meth:`vertex_normals` when ``smooth_normals``, else the
        corners' own; None for a part with no polygon left."""
        triangles, polygon = self.fan_triangles()
        smooth = self.vertex_normals() if smooth_normals else None
        out: list[MeshObject | None] = []
        for index, template in enumerate(templates):
            mine = triangles[self.part[polygon] == index]
            if not len(mine):
                out.append(None)
                continue
            used = mine.ravel()
            columns = [self.corners[used][:, None].astype(np.float64)]
            names = [name for name in ATTRIBUTES if name in self.attributes
                     and getattr(template, name) is not None and not (name == "vertex_normals" and smooth_normals)]
            columns += [self.attributes[name][used] for name in names]
            _, first, inverse = np.unique(np.concatenate(columns, axis=1), axis=0, return_index=True,
                                          return_inverse=True)
            chosen = used[first]
            twin = copy.copy(template)
            twin.forget_derived()
            twin.vertices = self.positions[self.corners[chosen]]
            twin.faces = inverse.reshape(-1, 3).astype(np.int64)
            for name in ATTRIBUTES:
                setattr(twin, name, self.attributes[name][chosen] if name in names else None)
            if template.vertex_normals is not None and smooth is not None:
                twin.vertex_normals = smooth[self.corners[chosen]]
            twin.validate()
            out.append(twin)
        return out


def weld(parts: list[MeshObject]) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """Welded positions (V, 3), the welded triangles (T, 3), each triangle's part (T,), and the per-corner
    attributes (T * 3, k) of all parts (an attribute only when every part has it)."""
    vertices = np.concatenate([part.vertices for part in parts])
    offsets = np.cumsum([0] + [len(part.vertices) for part in parts])
    faces = np.concatenate([part.faces + offset for part, offset in zip(parts, offsets)])
    positions, inverse = np.unique(vertices, axis=0, return_inverse=True)
    part = np.repeat(np.arange(len(parts)), [len(p.faces) for p in parts])
    attributes = {}
    for name in ATTRIBUTES:
        if all(getattr(p, name) is not None for p in parts):
            values = np.concatenate([np.asarray(getattr(p, name), dtype=np.float64) for p in parts])
            attributes[name] = values[faces.ravel()]
    return positions, inverse.reshape(-1)[faces], part, attributes


def from_parts(parts: list[MeshObject], polygons: bool = True) -> PolygonMesh:
    """The welded mesh of ``parts`` (module doc); ``polygons``: merge each loader-triangulated polygon back
    (:func:`hybridgen.scene.polygon_recovery.recover_polygons`), else keep the triangles."""
    from .polygon_recovery import recover_polygons

    positions, triangles, part, attributes = weld(parts)
    if polygons:
        loops, starts = recover_polygons(positions, triangles, part)
    else:
        loops, starts = np.arange(triangles.size), np.arange(0, triangles.size + 1, 3)
    polygon_part = part[loops[starts[:-1]] // 3]
    return PolygonMesh(positions, triangles.ravel()[loops], starts, polygon_part,
                       {name: values[loops] for name, values in attributes.items()})


_POLYGON_FACE = re.compile(rb"^f(?:[ \t]+\S+){4,}", re.MULTILINE)


def source_has_polygons(path: Any) -> bool:
    """Whether an object read from ``path`` may hold polygons of more than three corners, i.e. whether
    :func:`from_parts` should recover them: an OBJ with a face line of four or more vertices; not a PLY, STL or
    glTF (their loaders give triangles); an object of no file (a primitive) may."""
    if not isinstance(path, str) or not os.path.isfile(path):
        return True
    if not path.lower().endswith(".obj"):
        return False
    with open(path, "rb") as handle:
        return _POLYGON_FACE.search(handle.read()) is not None
