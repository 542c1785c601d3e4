"""Key translation of EntityManipulator (``cf_*`` functions, ``matrix_world``, ``cf_randomize_materials``) and
MaterialManipulator (``cf_set_*`` values, ``getter.Material`` selectors)."""
from __future__ import annotations

from typing import Any

from ...errors import ConfigError
from ...scene.principled_inputs import BY_BLENDER_NAME
from .common import Note, custom_properties, pop_ignored, pop_mode, take_shading
from .selectors import selector


def matrix_world(cfg: dict[str, Any]) -> None:
    """``matrix_world`` (4x4, metres) -> location, Euler XYZ rotation and scale."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    if "matrix_world" not in cfg:
        return
    try:
        matrix = np.asarray(cfg.pop("matrix_world"), dtype=np.float64).reshape(4, 4)
    except (TypeError, ValueError):
        raise ConfigError("must be a 4x4 matrix", key="matrix_world") from None
    linear = matrix[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale == 0) or not np.all(np.isfinite(matrix)):
        raise ConfigError("must be an invertible, finite 4x4 matrix", key="matrix_world")
    rotation = linear / scale
    if np.linalg.det(rotation) < 0:
        scale[0], rotation[:, 0] = -scale[0], -rotation[:, 0]
    if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-4):
        raise ConfigError("must be a rotation times a per-axis scale (no shear)", key="matrix_world")
    cfg.setdefault("location", matrix[:3, 3].tolist())
    cfg.setdefault("rotation", Rotation.from_matrix(rotation).as_euler("xyz").tolist())
    if "scale" in cfg:  # BlenderProc sets matrix_world, then scale on top of it
        given = np.broadcast_to(np.asarray(cfg["scale"], dtype=np.float64), (3,))
        cfg["scale"] = (scale * given).tolist()
    else:
        cfg["scale"] = scale.tolist()


def entity(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    if "selector" in cfg:
        cfg["selector"] = selector(cfg["selector"], note)
    props = {k: cfg.pop(k) for k in list(cfg) if k.startswith("cp_")}
    custom_properties(props, cfg)
    if "rotation_euler" in cfg:
        cfg["rotation"] = cfg.pop("rotation_euler")
    matrix_world(cfg)
    mode = cfg.get("mode")
    if "cf_randomize_materials" in cfg:
        cfg.pop("mode", None)  # the randomizer draws once for all or for each, as BlenderProc
    pop_mode(cfg, note)
    shading = take_shading(cfg)
    pop_ignored(cfg, "cf_add_modifier", note, "Blender's Solidify modifier is not applied to v1 configs' objects")
    pop_ignored(cfg, "cf_add_uv_mapping", note, "UV projection is not applied (the displacement reads LOCAL "
                "coordinates, as BlenderProc's)")
    displace(cfg, note)
    out = []
    randomize = cfg.pop("cf_randomize_materials", None)
    if randomize is not None:
        if not isinstance(randomize, dict):
            raise ConfigError("must be a mapping {randomization_level, materials_to_replace_with}",
                              key="cf_randomize_materials")
        extra = [k for k in randomize if k not in ("randomization_level", "materials_to_replace_with")]
        if extra:
            raise ConfigError(f"unknown key {extra[0]!r}; hybridgen takes randomization_level and "
                              "materials_to_replace_with", key="cf_randomize_materials")
        source = randomize.get("materials_to_replace_with")
        if isinstance(source, dict):
            source = {k: v for k, v in source.items() if k != "check_empty"}
        out.append(("manipulators.MaterialRandomizer", {
            "selector": cfg.get("selector", {"conditions": {}}),
            "randomization_level": randomize.get("randomization_level", 0.2),
            "materials_to_replace_with": source, "mode": mode or "once_for_each"}))
    if shading is not None:
        out.append(("object.Shading", {**shading, "selector": cfg.get("selector", {"conditions": {}})}))
    if set(cfg) - {"selector"} or not out:
        out.insert(0, ("manipulators.EntityManipulator", cfg))
    return out


DISPLACE_KEYS = ("texture", "mid_level", "subdiv_level", "strength", "min_vertices_for_subdiv")
"""The keys BlenderProc 1.x's cf_add_displace_modifier_with_texture reads (it ignores any other)."""


def displace(cfg: dict[str, Any], note: Note) -> None:
    """``cf_add_displace_modifier_with_texture`` -> EntityManipulator's ``displace`` (Subdivision Surface + Displace
    modifiers, hybridgen/scene/displacement.py); keys BlenderProc does not read are reported and dropped."""
    value = cfg.pop("cf_add_displace_modifier_with_texture", None)
    if value is None:
        return
    if not isinstance(value, dict):
        raise ConfigError("must be a mapping {texture, mid_level, subdiv_level, strength, min_vertices_for_subdiv}",
                          key="cf_add_displace_modifier_with_texture")
    for key in value:
        if key not in DISPLACE_KEYS:
            note(f"ignored: BlenderProc reads only {', '.join(DISPLACE_KEYS)}",
                 f"cf_add_displace_modifier_with_texture.{key}")
    cfg["displace"] = {key: value[key] for key in DISPLACE_KEYS if key in value}


_EXTRA_NAMES = {name: entry.key for name, entry in BY_BLENDER_NAME.items()}
_MATERIAL_VALUES = {"base_color": "base_color", "roughness": "roughness", "metallic": "metallic",
                    "specular": "specular", "ior": "ior", "alpha": "alpha", "transmission": "transmission",
                    "emission_strength": "emission_strength", "emission": "emission",
                    # coat, sheen, subsurface, anisotropy, specular tint: Blender 4 and Blender 3 input names
                    **{name.lower().replace(" ", "_"): key for name, key in _EXTRA_NAMES.items()}}


def material(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    sel = cfg.get("selector")
    if isinstance(sel, dict) and sel.get("provider") == "getter.Material":
        # materials are selected through the objects that carry them (hybridgen objects hold one material)
        conditions = sel.get("conditions", {})
        cfg["selector"] = {k: v for k, v in sel.items() if k not in ("provider", "conditions")}
        cfg["selector"]["conditions"] = _material_conditions(conditions)
        cfg["selector"].setdefault("check_empty", False)
    elif "selector" in cfg:
        cfg["selector"] = selector(cfg["selector"], note)
    pop_mode(cfg, note)
    values = dict(cfg.pop("material", {}) or {})
    for key in list(cfg):
        if not key.startswith("cf_"):
            continue
        function = key[3:]
        if function.startswith("set_"):
            name = function[4:].lower().replace(" ", "_")
            if name in _MATERIAL_VALUES:
                values[_MATERIAL_VALUES[name]] = cfg.pop(key)
                continue
        if function == "textures":
            values.update(_texture_maps(cfg.pop(key), note))
            continue
        if function == "color_link_to_displacement":
            cfg["color_link_to_displacement"] = cfg.pop(key)
            continue
        if function == "change_to_vertex_color":
            pop_ignored(cfg, key, note, "hybridgen keeps the lit principled material with the vertex colors as base "
                        "color (a mesh with vertex colors has it from loading); BlenderProc renders them unlit "
                        "(a Background shader)")
            continue
        if function == "add_dust":  # {strength, texture_scale, used_dust_texture} -> dust (config/dust_config.py)
            dust = dict(cfg.pop(key) or {})
            if "used_dust_texture" in dust:
                dust["texture"] = dust.pop("used_dust_texture")
            cfg["dust"] = dust
            continue
        if function == "infuse_texture":  # {used_texture, mode, ...} -> infuse_texture (config/infuse_config.py)
            infuse = dict(cfg.pop(key) or {})
            if "used_texture" in infuse:
                infuse["texture"] = infuse.pop("used_texture")
            cfg["infuse_texture"] = infuse
            continue
        if function == "switch_to_emission_shader":
            emission = cfg.pop(key) or {}
            color = emission.get("color", [1.0, 1.0, 1.0, 1.0]) if isinstance(emission, dict) else [1, 1, 1, 1]
            values["emission"] = color[:3] if isinstance(color, list) else color
            values["emission_strength"] = emission.get("strength", 1.0) if isinstance(emission, dict) else 1.0
            continue
        pop_ignored(cfg, key, note, f"Blender node-graph function '{function}' has no counterpart in hybridgen's "
             "principled material")
    cfg["material"] = values
    return [("manipulators.MaterialManipulator", cfg)]


_TEXTURE_INPUTS = {"base color": "base_color_texture", "roughness": "roughness_texture",
                   "metallic": "metallic_texture", "specular": "specular_texture", "alpha": "alpha_texture",
                   "emission": "emission_texture"}
"""Principled BSDF inputs cf_textures links an image to, and the hybridgen map that takes it."""


def _texture_maps(textures: Any, note: Note) -> dict[str, Any]:
    """``cf_textures`` ({Blender input name: image path or sampler}) as hybridgen material maps; inputs
    without a map in hybridgen are reported."""
    if not isinstance(textures, dict):
        raise ConfigError("must be a mapping {principled input name: image path}", key="cf_textures")
    maps = {}
    for name, path in textures.items():
        target = _TEXTURE_INPUTS.get(str(name).replace("_", " ").lower())
        if target is None:
            note("ignored: hybridgen maps images to Base Color, Roughness, Metallic, Specular, Alpha and Emission "
                 "(normal and displacement maps: material normal_texture / displacement_texture)",
                 f"cf_textures.{name}")
            continue
        maps[target] = path
    return maps


def _material_conditions(conditions: Any) -> Any:
    if isinstance(conditions, list):
        return [_material_conditions(c) for c in conditions]
    if not isinstance(conditions, dict):
        return conditions
    return {("material_name" if k == "name" else k): v for k, v in conditions.items()}
