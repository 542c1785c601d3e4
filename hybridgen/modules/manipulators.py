"""``manipulators.MaterialManipulator`` and ``manipulators.EntityManipulator``: change selected objects'
materials and poses/attributes, with values from samplers (drawn per object)."""
from __future__ import annotations

import dataclasses

import numpy as np

from ..config.displacement_config import displacement_from_config
from ..config.dust_config import dust_layer, with_dust
from ..config.infuse_config import infused
from ..config.material_config import apply_material_config
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import InputError
from ..scene.frames import object_pose
from ..run.context import RunContext
from ..scene.material import TEXTURE_SLOTS, Material
from ..scene.mesh_object import MeshObject
from ..scene.displacement import displace_object
from ..scene.frames import matrix_to_euler_xyz
from .base import Role
from .selecting import SelectingModule


@register_module("manipulators.MaterialManipulator")
class MaterialManipulator(SelectingModule):
    """Sets principled values (and textures, e.g. from sampler.Path over a folder) on selected objects."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="which objects (getter.Entity conditions, random_samples)"),
        Param("material", "dict", sampleable=True, doc="principled values: base_color, roughness, metallic, "
              "specular, transmission, ior, alpha, alpha_mode, emission, emission_strength, and maps (paths): "
              "base_color_texture, roughness_texture, metallic_texture, alpha_texture, normal_texture "
              "(normal_y_down), displacement_texture (displacement_scale), specular_texture, emission_texture, "
              "coat_normal_texture (the coat's own normal map); "
              "Blender's other Principled inputs in snake case: specular_tint, anisotropic, anisotropic_rotation, "
              "coat_weight, coat_roughness, coat_ior, coat_tint, sheen_weight, sheen_roughness, sheen_tint, "
              "subsurface_weight, subsurface_radius, subsurface_scale, subsurface_ior, subsurface_anisotropy, "
              "subsurface_method (docs/principled_bsdf.md)"),
        Param("randomize_color", "bool", False, doc="a uniform random base color per object"),
        Param("color_link_to_displacement", "float|null", None, "m", sampleable=True,
              doc="BlenderProc's cf_color_link_to_displacement: the material's base-color image becomes its "
                  "displacement (bump) map, scaled by this factor"),
        Param("infuse_texture", "dict|null", None, sampleable=True,
              doc="BlenderProc's cf_infuse_texture: an image blended into the base color, {texture: an image path / "
                  "getter.Texture, mode: overlay (a MIX blend, as BlenderProc's code runs) | mix (OVERLAY) | set, "
                  "connection: Base Color, strength: 0.5, texture_scale: 0.05, invert_texture: false} "
                  "(hybridgen/scene/infused_texture.py)"),
        Param("dust", "dict|null", None, sampleable=True,
              doc="BlenderProc's cf_add_dust: a dust film over the material, {strength, texture_scale: 0.1, "
                  "texture: null (generated noise) or an image path / getter.Texture} (hybridgen/scene/dust.py)"),
    )

    def run(self, context: RunContext) -> None:
        for obj in self.selected(context):
            values = dict(self.value(context, "material"))
            if self.config["randomize_color"]:
                values["base_color"] = [*context.rng.uniform(0, 1, 3).tolist(), 1.0]
            mapped = [key for key in TEXTURE_SLOTS if values.get(key) is not None]
            if mapped and obj.uvs is None:
                raise InputError(f"object '{obj.name}' has no UVs to map {mapped[0]} with")
            obj.material = apply_material_config(obj.material, values)
            factor = self.value(context, "color_link_to_displacement")
            if factor is not None:
                obj.material = linked_displacement(obj.material, float(factor), obj.name)
            infuse = self.value(context, "infuse_texture")
            if infuse is not None:
                obj.material = infused(obj.material, infuse, context.rng, context.scene.textures)
            dust = self.value(context, "dust")
            if dust is not None:
                obj.material = with_dust(obj.material, dust_layer(dust, context.rng, context.scene.textures))


def linked_displacement(material: Material, factor: float, owner: str) -> Material:
    """``material`` with its base-color image as displacement map scaled by ``factor`` (BlenderProc's
    cf_color_link_to_displacement: image color x factor into the material output's displacement, which Cycles
    renders as a bump; a constant offset changes no bump, so hybridgen's mid-level 0.5 gives the same shading;
    the Math node reads the color's linear luminance: ``displacement_from_color``). A material without a
    base-color image is an error, as in BlenderProc."""
    if material.base_color_texture is None:
        raise InputError(f"object '{owner}': material '{material.name}' has no base-color image to link to "
                         "displacement (color_link_to_displacement)")
    return dataclasses.replace(material, displacement_texture=material.base_color_texture,
                               displacement_scale=factor, displacement_from_color=True)


@register_module("manipulators.EntityManipulator")
class EntityManipulator(SelectingModule):
    """Sets the pose (location, rotation, scale) and custom attributes of selected objects."""

    role = Role.MANIPULATOR

    params = (
        Param("selector", "dict|list", doc="which objects (getter.Entity conditions, random_samples)"),
        Param("location", "vec3|null", None, "m", "new world position", sampleable=True),
        Param("rotation", "vec3|null", None, "rad", "new Euler XYZ rotation", sampleable=True),
        Param("scale", "float|list|null", None, doc="new scale", sampleable=True),
        Param("attributes", "dict", {}, sampleable=True, doc="custom attributes to set (e.g. for map_by)"),
        Param("category_id", "int|null", None, doc="new category_id"),
        Param("displace", "dict|null", None, sampleable=True,
              doc="true geometric displacement (Blender's Subdivision Surface + Displace modifiers, BlenderProc's "
                  "cf_add_displace_modifier_with_texture): {texture: sampler.Texture / a procedural texture name "
                  "(CLOUDS, VORONOI, ...) / a height image path (getter.Texture), strength: 0.1, mid_level: 0.5, "
                  "subdiv_level: 2 (Catmull-Clark, capped at 3), min_vertices_for_subdiv: 10000, texture_coords: "
                  "LOCAL|UV}, drawn once per Blender object; labels and color see the displaced mesh "
                  "(hybridgen/scene/displacement.py)"),
    )

    def run(self, context: RunContext) -> None:
        selected = self.selected(context)
        if self.config["displace"] is not None:
            displaced: dict = {}  # objects sharing a mesh and modifier share one displaced mesh
            for parts in blender_objects(selected):
                displace = self.value(context, "displace")
                if displace is not None:
                    modifier = displacement_from_config(displace, textures=context.scene.textures)
                    displace_object(parts, modifier, displaced)
        for obj in selected:
            location, rotation, scale = (self.value(context, k) for k in ("location", "rotation", "scale"))
            if location is not None or rotation is not None or scale is not None:
                current = obj.local2world
                linear = current[:3, :3]
                old_scale = np.linalg.norm(linear, axis=0)
                old_rotation = matrix_to_euler_xyz(linear / old_scale)
                obj.local2world = object_pose(current[:3, 3] if location is None else location,
                                              old_rotation if rotation is None else rotation,
                                              old_scale if scale is None else scale)
            obj.attributes.update(self.value(context, "attributes"))
            if self.config["category_id"] is not None:
                obj.category_id = self.config["category_id"]


def blender_objects(objects: list[MeshObject]) -> list[list[MeshObject]]:
    """``objects`` grouped into Blender objects: the parts a loader made of one object with several materials
    (same name and file, ``material_part`` set) together, in their order; every other object alone."""
    groups: dict[object, list[MeshObject]] = {}
    for obj in objects:
        key = (obj.name, obj.attributes.get("source_path")) if "material_part" in obj.attributes else id(obj)
        groups.setdefault(key, []).append(obj)
    return list(groups.values())
