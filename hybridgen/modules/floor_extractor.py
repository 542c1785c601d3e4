"""``object.FloorExtractor``: split the floor (or ceiling) faces of selected objects into their own object.

BlenderProc's FloorExtractor, for scenes loaded as one mesh: of each selected object, the faces whose world
normal is within ``compare_angle_degrees`` of world +Z (-Z with ``up_vector_upwards: false``) and whose
centre lies within ``compare_height`` (m) of the lowest (highest) such face become a new object named
``name_for_split_obj``, with the original's material and the ``add_properties`` (``cp_*``) attributes.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..config.blenderproc import custom_properties
from ..config.registry import register_module
from ..config.schema import Param, positive
from ..run.context import RunContext
from ..scene.face_slicing import split_faces
from ..scene.mesh_object import MeshObject
from .base import Role
from .selecting import SelectingModule


def floor_faces(obj: MeshObject, angle_deg: float, height: float, upwards: bool) -> np.ndarray:
    """Boolean mask of ``obj``'s floor (``upwards``) or ceiling faces, in world axes (see module doc)."""
    linear = obj.local2world[:3, :3]
    normals = obj.face_normals @ np.linalg.inv(linear)  # normals transform by the inverse transpose
    length = np.linalg.norm(normals, axis=1)
    normals = np.divide(normals, length[:, None], out=np.zeros_like(normals), where=length[:, None] > 0)
    up = np.array([0.0, 0.0, 1.0 if upwards else -1.0])
    facing = normals @ up >= math.cos(math.radians(angle_deg))
    if not np.any(facing):
        return facing
    centres = obj.world_vertices()[obj.faces].mean(axis=1)[:, 2]
    level = centres[facing].min() if upwards else centres[facing].max()
    return facing & (np.abs(centres - level) <= height)


@register_module("object.FloorExtractor")
class FloorExtractor(SelectingModule):
    """Splits the floor faces of the selected objects into a new object (BlenderProc's FloorExtractor)."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="objects to split the floor from (getter.Entity conditions)"),
        Param("compare_angle_degrees", "float", 7.5, "deg", "largest angle between a face normal and the up "
              "axis", check=lambda v: None if 0 <= v <= 90 else "must be in 0..90"),
        Param("compare_height", "float", 0.15, "m", "faces within this height of the lowest floor face",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("up_vector_upwards", "bool", True, doc="true: floor (normals up); false: ceiling (normals down)"),
        Param("name_for_split_obj", "str", "Floor", doc="name of the new object"),
        Param("add_properties", "dict", {}, doc="cp_* custom properties of the new object (cp_category_id "
              "sets its category_id)"),
        Param("should_skip_if_object_is_already_there", "bool", False,
              doc="do nothing when an object named name_for_split_obj exists"),
        Param("max_objects", "int", 1_000_000, doc="at most this many selected objects are split",
              check=positive),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        scene = context.scene
        if cfg["should_skip_if_object_is_already_there"] and any(
                o.name == cfg["name_for_split_obj"] for o in scene.objects):
            return
        labels: dict[str, Any] = {}
        custom_properties(cfg["add_properties"], labels)
        for obj in self.selected(context)[:cfg["max_objects"]]:
            mask = floor_faces(obj, cfg["compare_angle_degrees"], cfg["compare_height"], cfg["up_vector_upwards"])
            if not np.any(mask):
                context.log(f"FloorExtractor: '{obj.name}' has no floor faces")
                continue
            floor = split_faces(obj, mask, cfg["name_for_split_obj"])
            if "category_id" in labels:
                floor.category_id = labels["category_id"]
            floor.attributes.update(labels.get("attributes", {}))
            if not np.all(mask):
                scene.replace(obj, split_faces(obj, ~mask, obj.name))
            else:
                scene.remove(obj)
            scene.add(floor)
