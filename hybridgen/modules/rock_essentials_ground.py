"""``constructor.RockEssentialsGroundConstructor``: Rock Essentials ground tiles (BlenderProc 1.x's module of that
name): a plane cut into a grid, displaced and subdivided (:class:`hybridgen.scene.ground_tile.GroundTile`).

``tiles``: one dict per tile with BlenderProc's keys and defaults: ``shader_path`` (the pack's .blend holding
its "PBR Rock Shader" node group; it must exist), ``plane_scale`` ([1, 1, 1]: the 2 m plane's scale, applied),
``subdivision_cuts`` (50), ``subdivision_render_levels`` (3; capped at 3 as BlenderProc's renderer caps it),
``tile_name`` ("RE_ground_plane"). ``add_properties``: ``cp_*`` custom properties of every tile
(``cp_category_id`` the class). Each tile gets the attribute ``physics`` false and the material
``re_ground_mat``, whose image inputs ``materials.RockEssentialsTextureSampler`` fills. Until then it displaces
without an image, as Blender does: down by strength / 2 = 0.5 m.

The pack's node group is a product of its vendor and is not read: the sampler feeds its inputs (color x AO,
roughness, reflection, normal) to the Principled material as its input names say (module doc there).
"""
from __future__ import annotations

import os
from typing import Any

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..input_paths import resolve_input
from ..io.blender_names import unique_blender_name
from ..run.context import RunContext
from ..scene.ground_tile import GroundTile
from ..scene.material import Material
from ..scene.mesh_object import MeshObject
from .base import Module, Role
from .dataset_support import add_properties

STATE_KEY = "rock_essentials_ground"
"""``RunContext.module_state[STATE_KEY]``: {tile name: GroundTile}."""
TILE_KEYS = {"shader_path": str, "plane_scale": list, "subdivision_cuts": int, "subdivision_render_levels": int,
             "tile_name": str}
GROUND_MATERIAL = "re_ground_mat"


def _tiles_check(value: Any) -> str | None:
    if not isinstance(value, list):
        return f"must be a list of tile dicts, got {value!r}"
    for i, tile in enumerate(value):
        if not tile:
            continue  # BlenderProc skips empty entries
        if not isinstance(tile, dict) or "shader_path" not in tile:
            return f"tile {i} must be a dict with a 'shader_path', got {tile!r}"
        for key, item in tile.items():
            if key not in TILE_KEYS:
                return f"tile {i}: unknown key '{key}' (known: {', '.join(TILE_KEYS)})"
            if not isinstance(item, TILE_KEYS[key]) or isinstance(item, bool):
                return f"tile {i}: '{key}' has the wrong type ({item!r})"
        if "plane_scale" in tile and (len(tile["plane_scale"]) != 3
                                      or not all(isinstance(v, (int, float)) for v in tile["plane_scale"])):
            return f"tile {i}: 'plane_scale' must be [x, y, z], got {tile['plane_scale']!r}"
        if tile.get("subdivision_cuts", 50) < 0 or tile.get("subdivision_render_levels", 3) < 0:
            return f"tile {i}: subdivision_cuts and subdivision_render_levels must be >= 0"
    return None


def tile_object(name: str, tile: GroundTile, material: Material) -> MeshObject:
    """The scene object of ``tile`` (flat-shaded, object frame = world frame at the origin)."""
    vertices, faces, uvs = tile.mesh(name)
    return MeshObject(name=name, vertices=vertices, faces=faces, uvs=uvs, material=material)


@register_module("constructor.RockEssentialsGroundConstructor")
class RockEssentialsGroundConstructor(Module):
    """Builds Rock Essentials ground tiles (module doc)."""

    role = Role.LOADER

    params = (
        Param("tiles", "list", [], check=_tiles_check, doc="one dict per tile (module doc for its keys)"),
        Param("add_properties", "dict", {}, doc="custom properties of every tile (cp_category_id: the class)"),
    )

    def run(self, context: RunContext) -> None:
        tiles = context.module_state.setdefault(STATE_KEY, {})
        for index, spec in enumerate(self.config["tiles"]):
            if not spec:
                continue
            key = f"tiles[{index}].shader_path"
            if not os.path.isfile(resolve_input(spec["shader_path"], key, noun="Rock Essentials .blend file")):
                raise ConfigError(f"Rock Essentials .blend file not found: '{spec['shader_path']}'", key=key)
            scale = tuple(float(v) for v in spec.get("plane_scale", [1, 1, 1]))
            tile = GroundTile(plane_scale=scale, cuts=int(spec.get("subdivision_cuts", 50)),  # type: ignore[arg-type]
                              levels=int(spec.get("subdivision_render_levels", 3)))
            taken = {o.name for o in context.scene.objects}
            name = unique_blender_name(spec.get("tile_name", "RE_ground_plane"), taken)
            obj = tile_object(name, tile, Material(name=GROUND_MATERIAL))
            obj.attributes["physics"] = False
            add_properties([obj], self.config["add_properties"])
            tiles[name] = tile
            context.scene.add(obj)

