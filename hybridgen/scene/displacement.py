"""True geometric displacement of a scene object: Blender's Subdivision Surface + Displace modifiers as BlenderProc
1.x's EntityManipulator ``cf_add_displace_modifier_with_texture`` adds them (hybridgen's v1 ``displace``), on the
implementation bproc's ``MeshObject.add_displace_modifier`` uses too; color, depth, normals and every other label
see the displaced surface.

One Blender object is one or more hybridgen parts (a part per material, same name; local frame, metres). As
Blender evaluates the modifiers for a render:

1. The parts are welded into Blender's polygon mesh (:func:`hybridgen.scene.polygon_mesh.from_parts`): one vertex
   per position, the quads and n-gons a loader triangulated recovered (not for files that hold only triangles).
2. When the mesh has at most ``min_vertices_for_subdiv`` vertices (Blender's count), a Subdivision Surface of
   ``subdiv_level`` render levels, capped at ``simplify`` (BlenderProc's Initializer sets Blender's Simplify to
   3; 0: no cap), with Blender's defaults: Catmull-Clark, boundaries and corners smoothed, vertices on the limit
   surface (:mod:`hybridgen.scene.catmull_clark`; a coarse cube becomes a rounded box, a plane's corners pull in);
   ``subdivision`` SIMPLE subdivides without smoothing.
3. The Displace modifier (:mod:`hybridgen.scene.displace_modifier`): every vertex moves by
   ``strength x (t - mid_level)`` metres along its vertex normal (corner-angle weighted, of the subdivided mesh),
   ``t`` the texture at the vertex's ``texture_coords``: LOCAL (Blender's default, which BlenderProc keeps: the
   vertex in Blender's mesh frame), UV or GLOBAL. Textures (:mod:`hybridgen.scene.displacement_texture`): an
   image (:class:`~hybridgen.scene.displacement_texture.ImageHeight`, read as Blender reads it: LOCAL x, y in
   [-1, 1] span it once) or one of Blender's procedural textures
   (:class:`~hybridgen.scene.displacement_texture.ProceduralHeight`: CLOUDS, VORONOI, ... of ``sampler.Texture``).
4. The mesh goes back into the parts, triangulated; smooth-shaded parts get the displaced mesh's vertex normals
   (Blender's), flat-shaded ones stay flat.

Blender's mesh frame: Blender's OBJ importer (the one BlenderProc 1.x and 2.x call) keeps the file's Y-up
coordinates in the mesh and turns the object instead, where hybridgen's v1 loader turns the vertices Z-up; so for
an object read from an OBJ file LOCAL coordinates are taken in the file's frame (:func:`mesh_frame`; an OBJ
loaded with ``up_axis: Z`` is taken as turned too). Measured with bpy 4.2 (tools/blender_displace_image.py).

Objects sharing one mesh (the same arrays: instances of one model) and one modifier get one displaced mesh,
computed once and shared (:func:`displace_object` with one ``done`` dict), so instancing still holds - except
for GLOBAL coordinates and white NOISE, whose values differ per object.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from .displacement_texture import Texture, texture_key
from .frames import Y_UP_TO_Z_UP
from .mesh_object import MeshObject

TEXTURE_COORDS = ("LOCAL", "UV", "GLOBAL")
SUBDIVISIONS = ("CATMULL_CLARK", "SIMPLE")


@dataclass(frozen=True)
class Displacement:
    """The Subdivision + Displace modifiers (BlenderProc's names and defaults; module doc). ``texture`` None reads
    1 everywhere (Blender's Displace without a texture)."""

    texture: Texture | None
    strength: float = 0.1
    mid_level: float = 0.5
    subdiv_level: int = 2
    min_vertices_for_subdiv: int = 10000
    texture_coords: str = "LOCAL"
    subdivision: str = "CATMULL_CLARK"
    simplify: int = 3

    def check(self, owner: str) -> None:
        """One-line errors for values that cannot displace."""
        if self.texture_coords not in TEXTURE_COORDS:
            raise InputError(f"object '{owner}': displacement texture_coords must be one of "
                             f"{', '.join(TEXTURE_COORDS)}, got {self.texture_coords!r}")
        if self.subdivision not in SUBDIVISIONS:
            raise InputError(f"object '{owner}': displacement subdivision must be one of {', '.join(SUBDIVISIONS)}, "
                             f"got {self.subdivision!r}")
        if not (0 <= self.subdiv_level <= 8):
            raise InputError(f"object '{owner}': displacement subdiv_level must be in 0..8, got {self.subdiv_level}")
        if not (np.isfinite(self.strength) and np.isfinite(self.mid_level)):
            raise InputError(f"object '{owner}': displacement strength and mid_level must be finite")

    @property
    def levels(self) -> int:
        """The subdivision levels Blender renders: ``subdiv_level`` capped at ``simplify`` (0: no cap)."""
        return min(self.subdiv_level, self.simplify) if self.simplify > 0 else self.subdiv_level

    def key(self) -> tuple[Any, ...]:
        """Hashable identity (the texture by :func:`~hybridgen.scene.displacement_texture.texture_key`)."""
        return (texture_key(self.texture), self.strength, self.mid_level, self.levels, self.min_vertices_for_subdiv,
                self.texture_coords, self.subdivision)


def mesh_frame(part: MeshObject) -> np.ndarray | None:
    """The 4x4 from ``part``'s local frame to Blender's mesh frame (module doc): the inverse Y-up turn for a part
    read from an OBJ file, else None (the same frame)."""
    source = part.attributes.get("source_path")
    if isinstance(source, str) and source.lower().endswith(".obj"):
        return Y_UP_TO_Z_UP.T.copy()
    return None


def blender_vertex_count(parts: list[MeshObject]) -> int:
    """Blender's vertex count of the object: its parts' vertices welded by position."""
    return len(np.unique(np.concatenate([p.vertices for p in parts]), axis=0))


def displaced_parts(parts: list[MeshObject], modifier: Displacement,
                    local2world: np.ndarray | None = None) -> list[MeshObject]:
    """New parts: ``parts`` (one Blender object) after the modifiers (module doc)."""
    from .catmull_clark import subdivide
    from .displace_modifier import displace
    from .polygon_mesh import from_parts, source_has_polygons

    owner = parts[0].name
    modifier.check(owner)
    if modifier.texture_coords == "UV" and any(p.uvs is None for p in parts):
        raise InputError(f"object '{owner}' has no UVs for its displacement texture (texture_coords UV)")
    mesh = from_parts(parts, polygons=source_has_polygons(parts[0].attributes.get("source_path")))
    if len(mesh.positions) <= modifier.min_vertices_for_subdiv:
        smooth = modifier.subdivision == "CATMULL_CLARK"
        mesh = subdivide(mesh, modifier.levels, limit=smooth, smooth=smooth)
    moved = displace(mesh, modifier.texture, modifier.strength, modifier.mid_level, "NORMAL",
                     modifier.texture_coords, parts[0].local2world if local2world is None else local2world,
                     mesh_frame(parts[0]))
    out = moved.to_parts(parts)
    if any(part is None for part in out):  # not expected: displacement keeps every polygon
        raise InputError(f"object '{owner}': a part lost all its faces in the displacement")
    return out  # type: ignore[return-value]


_ARRAYS = ("vertices", "faces", "uvs", "vertex_normals", "vertex_colors")


def displace_object(parts: list[MeshObject], modifier: Displacement,
                    done: dict[tuple[Any, ...], tuple[list[Any], list[MeshObject]]] | None = None) -> None:
    """Replace the meshes of ``parts`` (one Blender object) by their displaced meshes, in place. ``done`` carries
    the results across calls (one dict per manipulator run): parts sharing their arrays (and the modifier, and for
    GLOBAL coordinates the pose) share the result's arrays."""
    done = {} if done is None else done
    key = (tuple(tuple(id(getattr(p, name)) for name in _ARRAYS) for p in parts), modifier.key(),
           parts[0].local2world.tobytes() if modifier.texture_coords == "GLOBAL" else None,
           None if mesh_frame(parts[0]) is None else "obj")
    if key not in done:  # the source arrays are kept with the result, so their ids stay theirs
        done[key] = ([getattr(p, name) for p in parts for name in _ARRAYS], displaced_parts(parts, modifier))
    for part, result in zip(parts, done[key][1]):
        for name in _ARRAYS:
            setattr(part, name, getattr(result, name))
        part.forget_derived()
        part.validate()
