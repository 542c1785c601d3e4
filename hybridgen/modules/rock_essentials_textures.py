"""``materials.RockEssentialsTextureSampler``: a random Rock Essentials ground texture for each selected ground tile
(BlenderProc 1.x's module of that name; the tiles come from ``constructor.RockEssentialsGroundConstructor``).

``selector``: the tiles (getter.Entity; every one must carry the ``re_ground_mat`` material). ``textures``: a
list of dicts, one drawn uniformly per tile, with BlenderProc's keys and defaults: ``path`` (the texture's
folder), ``images`` ({map: file name in that folder}: ``color`` sRGB, the others read as data: ``roughness``,
``reflection``, ``normal``, ``displacement``), ``uv_scaling`` (1: the tile's UVs are multiplied by it, so every
map repeats that often), ``ambient_occlusion`` ([1, 1, 1, 1]: multiplies the color), ``displacement_strength``
(1: metres per unit of height of the tile's Displace modifier; the tile is evaluated again,
:class:`hybridgen.scene.ground_tile.GroundTile`).

The pack's "PBR Rock Shader" node group is not public; its inputs are mapped as their names say: color x AO ->
base color, roughness -> roughness, reflection -> Specular IOR Level, normal -> a tangent-space normal map
(Blender's Normal Map node: OpenGL convention).
"""
from __future__ import annotations

import os
from typing import Any

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import InputError
from ..input_paths import resolve_input
from ..run.context import RunContext
from ..scene.material import Material
from ..scene.mesh_object import MeshObject
from .base import Role
from .rock_essentials_ground import GROUND_MATERIAL, STATE_KEY
from .selecting import SelectingModule

MAPS = ("color", "roughness", "reflection", "normal", "displacement")
TEXTURE_KEYS = ("path", "images", "uv_scaling", "ambient_occlusion", "displacement_strength")


def _textures_check(value: Any) -> str | None:
    if not isinstance(value, list) or not value:
        return f"must be a non-empty list of texture dicts, got {value!r}"
    for i, texture in enumerate(value):
        if not isinstance(texture, dict) or "path" not in texture or not isinstance(texture.get("images"), dict):
            return f"texture {i} must be a dict with 'path' and 'images', got {texture!r}"
        unknown = [k for k in texture if k not in TEXTURE_KEYS] + [k for k in texture["images"] if k not in MAPS]
        if unknown:
            return f"texture {i}: unknown key(s) {unknown} (known: {TEXTURE_KEYS}, images: {MAPS})"
        ao = texture.get("ambient_occlusion", [1, 1, 1, 1])
        if not isinstance(ao, list) or len(ao) not in (3, 4) or not all(isinstance(c, (int, float)) for c in ao):
            return f"texture {i}: 'ambient_occlusion' must be [r, g, b, a], got {ao!r}"
        for key in ("uv_scaling", "displacement_strength"):
            if key in texture and (isinstance(texture[key], bool) or not isinstance(texture[key], (int, float))):
                return f"texture {i}: '{key}' must be a number, got {texture[key]!r}"
    return None


def tinted_color(path: str, ao: list[float]) -> Any:
    """The color image (sRGB) multiplied by the AO color in linear light; the path itself when AO is white."""
    if all(float(c) == 1.0 for c in ao[:3]):
        return path
    from PIL import Image

    from ..render.tonemap import srgb_decode, to_srgb8

    with Image.open(path) as image:
        rgb = np.asarray(image.convert("RGB"), dtype=np.float64) / 255.0
    return to_srgb8(srgb_decode(rgb) * np.asarray(ao[:3], dtype=np.float64))


@register_module("materials.RockEssentialsTextureSampler")
class RockEssentialsTextureSampler(SelectingModule):
    """Gives ground tiles a random Rock Essentials texture (module doc)."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="the ground tiles (getter.Entity)"),
        Param("textures", "list", check=_textures_check, doc="texture dicts, one drawn per tile (module doc)"),
    )

    def run(self, context: RunContext) -> None:
        tiles = context.module_state.get(STATE_KEY, {})
        for obj in self.selected(context):
            if obj.material.name != GROUND_MATERIAL or obj.name not in tiles:
                raise InputError(f"{self.module_name}: '{obj.name}' has no Rock Essentials ground material "
                                 f"'{GROUND_MATERIAL}'; run constructor.RockEssentialsGroundConstructor first")
            spec = self.config["textures"][int(context.rng.integers(len(self.config["textures"])))]
            self._apply(obj, tiles[obj.name], spec)

    def _apply(self, obj: MeshObject, tile: Any, spec: dict[str, Any]) -> None:
        images = {key: resolve_input(os.path.join(spec["path"], name), f"textures.images.{key}", noun="texture")
                  for key, name in spec["images"].items()}
        material = Material(name=obj.material.name)
        if "color" in images:
            material.base_color_texture = tinted_color(images["color"], list(spec.get("ambient_occlusion",
                                                                                      [1, 1, 1, 1])))
        material.roughness_texture = images.get("roughness")
        material.specular_texture = images.get("reflection")
        material.normal_texture = images.get("normal")
        tile.uv_scaling = float(spec.get("uv_scaling", 1.0))
        tile.strength = float(spec.get("displacement_strength", 1.0))
        tile.height = images.get("displacement", tile.height)
        obj.set_geometry(*tile.mesh(obj.name))
        obj.material = material
