"""``loader.ObjLoader``: a mesh file (obj+mtl, ply, stl, glb/gltf, off) into the scene, read as Blender reads it."""
from __future__ import annotations

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..io.mesh_cache import load_objects_cached
from ..io.mesh_loader import LOADERS, unique_blender_name
from ..run.context import RunContext
from .base import Module, Role
from .placement import PLACEMENT_PARAMS, apply_placement, drawn_placement, placement_pose


@register_module("loader.ObjLoader")
class ObjLoader(Module):
    """Loads one mesh file; every object of it (OBJ ``o``, glTF node) becomes an object with a stable instance id.

    Without ``name``, objects get Blender's names; a name already in the scene gets Blender's ``.001`` suffix.
    """

    role = Role.LOADER

    params = (
        Param("path", "path", doc=f"mesh file ({', '.join(LOADERS)}); relative to the working directory, else to "
              "the config's folder"),
        *PLACEMENT_PARAMS,
        Param("up_axis", "str", "auto", choices=("auto", "Y", "Z"),
              doc="the file's up axis; auto: as Blender's importers read the format - Y for OBJ "
                  "(axis_forward -Z, axis_up Y) and glTF, Z (as stored) for PLY, STL, OFF"),
    )

    def run(self, context: RunContext) -> None:
        cfg = drawn_placement(self, context)
        objects = load_objects_cached(cfg["path"], name=cfg["name"], category_id=cfg["category_id"],
                                      local2world=placement_pose(cfg), up_axis=cfg["up_axis"],
                                      attributes=cfg["attributes"],
                                      notify=lambda line: notice(line, module=self.module_name, index=self.index))
        add_with_blender_names(context, apply_placement(objects, cfg), renamed=cfg["name"] is None)


def add_with_blender_names(context: RunContext, objects: list, *, renamed: bool) -> None:
    """Add ``objects`` to the scene; with ``renamed``, a name already taken gets Blender's next ``.NNN``."""
    taken = {o.name for o in context.scene.objects}
    given: dict[str, str] = {}
    for obj in objects:
        if renamed:
            if obj.name not in given:
                given[obj.name] = unique_blender_name(obj.name, taken | set(given.values()))
            obj.name = given[obj.name]
        context.scene.add(obj)
