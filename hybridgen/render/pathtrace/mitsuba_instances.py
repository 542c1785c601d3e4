"""Mitsuba instancing of shared geometry (:mod:`hybridgen.render.shared_geometry`): one ``shapegroup`` holding
the mesh in its local frame with its BSDF, one ``instance`` per placement with ``to_world = local2world``.
Emissive objects stay separate shapes (Mitsuba's shape groups hold no emitters)."""
from __future__ import annotations

import copy
from typing import Any, Callable

import numpy as np

from ...scene.mesh_object import MeshObject
from ..shared_geometry import shared_groups


def instanced_entries(objects: list[MeshObject], mesh_shape: Callable[[MeshObject], Any],
                      emissive: Callable[[MeshObject], bool]) -> tuple[dict[str, Any], set[int]]:
    """Scene-dictionary entries for the shared geometry of ``objects`` and the instance ids they cover.

    ``mesh_shape`` builds a Mitsuba mesh of an object in world coordinates (it is given a copy placed at
    the identity, i.e. the local frame).
    """
    import mitsuba as mi

    entries: dict[str, Any] = {}
    covered: set[int] = set()
    for index, group in enumerate(shared_groups([o for o in objects if not emissive(o)])):
        local = copy.copy(group[0])
        local.local2world = np.eye(4)
        group_id = f"shared_{index}"
        entries[group_id] = {"type": "shapegroup", "shape": mesh_shape(local)}
        for obj in group:
            entries[f"object_{obj.instance_id}"] = {
                "type": "instance", "shapegroup": {"type": "ref", "id": group_id},
                "to_world": mi.ScalarTransform4f(obj.local2world.tolist())}
            covered.add(obj.instance_id)
    return entries, covered
