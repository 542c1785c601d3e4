"""Objects that share their geometry: the same vertex, face, normal, UV and vertex-color arrays (the same
Python objects, as a loader that places one parsed model many times hands them out) and equal materials
(field by field; image arrays by identity), so a material copied per object still shares.

The raster view uploads such geometry once and draws every placement from the same GPU buffers; the Mitsuba
scene holds it once in a ``shapegroup`` with one ``instance`` per placement. ``ENABLED`` is the switch
``tools/bench_assets.py`` turns off to measure the difference (outputs are the same either way, up to
float rounding of the transforms in Mitsuba).
"""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..scene.material import Material
from ..scene.mesh_object import MeshObject

ENABLED = True


def geometry_key(obj: MeshObject) -> tuple[Any, ...] | None:
    """Identity of ``obj``'s arrays and material; None when sharing is off."""
    if not ENABLED:
        return None
    return (id(obj.vertices), id(obj.faces), id(obj.vertex_normals), id(obj.uvs), id(obj.vertex_colors),
            material_key(obj.material))


def material_key(material: Material) -> tuple[Any, ...]:
    """A hashable value equal for materials with equal fields (arrays compared by identity)."""
    values = []
    for field in dataclasses.fields(material):
        value = getattr(material, field.name)
        if isinstance(value, np.ndarray):
            value = ("array", id(value))
        elif isinstance(value, dict):
            value = ("dict", id(value)) if value else ()
        elif isinstance(value, list):
            value = tuple(value)
        values.append(value)
    return tuple(values)


def shared_groups(objects: list[MeshObject]) -> list[list[MeshObject]]:
    """Groups of two or more objects with the same :func:`geometry_key`, in scene order."""
    groups: dict[tuple[Any, ...], list[MeshObject]] = {}
    for obj in objects:
        key = geometry_key(obj)
        if key is not None:
            groups.setdefault(key, []).append(obj)
    return [group for group in groups.values() if len(group) > 1]
