"""``loader.ObjLoader``: a mesh file (obj+mtl, ply, stl, glb/gltf, off) into the scene."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..io.mesh_loader import LOADERS, load_objects
from ..run.context import RunContext
from .base import Module
from .placement import PLACEMENT_PARAMS, apply_placement, drawn_placement, placement_pose


@register_module("loader.ObjLoader")
class ObjLoader(Module):
    """Loads one mesh file; every part becomes an object with a stable instance id."""

    params = (
        Param("path", "path", doc=f"mesh file ({', '.join(LOADERS)}); relative to the working directory"),
        *PLACEMENT_PARAMS,
        Param("up_axis", "str", "auto", choices=("auto", "Y", "Z"),
              doc="the file's up axis; auto: Y for glTF (its specification), Z otherwise"),
    )

    def run(self, context: RunContext) -> None:
        cfg = drawn_placement(self, context)
        objects = load_objects(cfg["path"], name=cfg["name"], category_id=cfg["category_id"],
                               local2world=placement_pose(cfg), up_axis=cfg["up_axis"],
                               attributes=cfg["attributes"])
        for obj in apply_placement(objects, cfg):
            context.scene.add(obj)
