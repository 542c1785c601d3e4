"""Analytic shapes as scene objects (metres, centred on the local origin, Z up)."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import InputError
from . import primitive_meshes
from .material import Material
from .mesh_object import MeshObject
from .primitive_meshes import Mesh
from .vertex_normals import angle_weighted_normals


PRIMITIVES: dict[str, Callable[[float], Mesh]] = {
    "cube": lambda size: primitive_meshes.box((size, size, size)),
    "sphere": lambda size: primitive_meshes.icosphere(subdivisions=4, radius=size / 2),
    "cylinder": lambda size: primitive_meshes.cylinder(radius=size / 2, height=size, sections=64),
    "cone": lambda size: primitive_meshes.cone(radius=size / 2, height=size, sections=64),
    "torus": lambda size: primitive_meshes.torus(major_radius=size * 0.35, minor_radius=size * 0.15),
    "plane": primitive_meshes.plane,
}
"""Shape name -> builder taking the size (edge length or diameter, metres) and returning (vertices, faces)
(NumPy only: building primitives never imports trimesh)."""

SMOOTH = {"sphere", "torus"}
"""Shapes whose shading normals are the smooth vertex normals; the others are flat-shaded."""


def make_primitive(shape: str, size: float = 1.0, *, name: str | None = None, category_id: int | None = None,
                   local2world: np.ndarray | None = None, color: tuple[float, ...] | None = None,
                   attributes: dict[str, Any] | None = None) -> MeshObject:
    """A primitive as a :class:`MeshObject`; the sphere's vertex normals are analytic (unit position), the
    torus' the angle-weighted face normals; the other shapes are flat-shaded."""
    if shape not in PRIMITIVES:
        raise InputError(f"unknown primitive {shape!r}; known: {sorted(PRIMITIVES)}")
    if not size > 0:
        raise InputError(f"primitive size must be > 0, got {size}")
    vertices, faces = PRIMITIVES[shape](float(size))
    material = Material(name=f"{shape}_material")
    if color is not None:
        rgba = tuple(float(c) for c in color) + (1.0,) * (4 - len(color))
        material.base_color = rgba[:4]  # type: ignore[assignment]
    return MeshObject(
        name=name or shape,
        vertices=vertices,
        faces=faces,
        vertex_normals=_sphere_normals(vertices) if shape == "sphere" else
        (angle_weighted_normals(vertices, faces) if shape in SMOOTH else None),
        material=material,
        category_id=category_id,
        attributes=dict(attributes or {}),
        local2world=np.eye(4) if local2world is None else local2world,
    )


def _sphere_normals(vertices: np.ndarray) -> np.ndarray:
    v = np.asarray(vertices, dtype=np.float64)
    return v / np.linalg.norm(v, axis=1, keepdims=True)
