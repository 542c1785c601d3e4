"""Analytic shapes as scene objects (metres, centred on the local origin, Z up)."""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..errors import InputError
from .material import Material
from .mesh_object import MeshObject


def _trimesh() -> Any:
    import trimesh

    return trimesh


PRIMITIVES: dict[str, Callable[[float], Any]] = {
    "cube": lambda size: _trimesh().creation.box(extents=[size] * 3),
    "sphere": lambda size: _trimesh().creation.icosphere(subdivisions=4, radius=size / 2),
    "cylinder": lambda size: _trimesh().creation.cylinder(radius=size / 2, height=size, sections=64),
    "cone": lambda size: _trimesh().creation.cone(radius=size / 2, height=size, sections=64),
    "torus": lambda size: _trimesh().creation.torus(major_radius=size * 0.35, minor_radius=size * 0.15),
    "plane": lambda size: _trimesh().Trimesh(
        vertices=np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float64) * size / 2,
        faces=np.array([[0, 1, 2], [0, 2, 3]])),
}
"""Shape name -> builder taking the size (edge length or diameter, metres)."""

SMOOTH = {"sphere", "torus"}
"""Shapes whose shading normals are the smooth vertex normals; the others are flat-shaded."""


def make_primitive(shape: str, size: float = 1.0, *, name: str | None = None, category_id: int | None = None,
                   local2world: np.ndarray | None = None, color: tuple[float, ...] | None = None,
                   attributes: dict[str, Any] | None = None) -> MeshObject:
    """A primitive as a :class:`MeshObject`; the sphere's and torus' vertex normals are analytic."""
    if shape not in PRIMITIVES:
        raise InputError(f"unknown primitive {shape!r}; known: {sorted(PRIMITIVES)}")
    if not size > 0:
        raise InputError(f"primitive size must be > 0, got {size}")
    mesh = PRIMITIVES[shape](float(size))
    material = Material(name=f"{shape}_material")
    if color is not None:
        rgba = tuple(float(c) for c in color) + (1.0,) * (4 - len(color))
        material.base_color = rgba[:4]  # type: ignore[assignment]
    return MeshObject(
        name=name or shape,
        vertices=np.asarray(mesh.vertices),
        faces=np.asarray(mesh.faces),
        vertex_normals=_sphere_normals(mesh.vertices) if shape == "sphere" else
        (np.asarray(mesh.vertex_normals) if shape in SMOOTH else None),
        material=material,
        category_id=category_id,
        attributes=dict(attributes or {}),
        local2world=np.eye(4) if local2world is None else local2world,
    )


def _sphere_normals(vertices: np.ndarray) -> np.ndarray:
    v = np.asarray(vertices, dtype=np.float64)
    return v / np.linalg.norm(v, axis=1, keepdims=True)
