"""Inputs of the diffuse-color variant of the albedo pass (``shaders/principled_diffuse.glsl``): Cycles' Diffuse
Color pass (DiffCol) of Blender 4.2's Principled BSDF at each pixel centre.

Cycles' DiffCol is the sum of the diffuse closures' weights: the Principled BSDF's diffuse (and subsurface)
closure, whose weight is the base color times what the layers above it leave - 1 - max(sheen albedo), the
coat's share and tint, (1 - metallic), (1 - transmission), 1 - max(the dielectric specular layer's albedo) from
the view direction - plus the sheen closure's albedo (sheen weight x tint x R(view cosine), a diffuse closure in
Cycles' classification). Measured with bpy 4.2 (tools/diffuse_color_vs_cycles.py): the path tracer's diffuse
weight (:mod:`hybridgen.render.pathtrace.principled_layers`) plus that sheen albedo equals DiffCol to 1e-4. The
shader repeats those steps with the path tracer's own tables (:mod:`hybridgen.render.principled_table_data`,
uploaded once per pass as one storage buffer). The view cosine is taken from the interpolated (or flat) mesh
normal and the ray through the pixel centre; normal and bump maps are not applied.

Per object this module sets the material's values (roughness, metallic, Specular IOR Level, IOR, transmission
and the ``extra`` inputs: specular tint, coat, sheen, subsurface) and uploads its roughness, metallic and
specular maps (linear data, bilinear, repeating, as the path tracer samples them).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ...scene.mesh_object import MeshObject
from ...scene.principled_inputs import DEFAULTS
from ..material_textures import data_image
from ..principled_table_data import host_tables

TABLES = ("ggx_E", "ggx_Eavg", "fresnel_avg", "schlick_s", "sheen_R")
"""The tables the shader reads (``PD_<NAME>`` offset and ``PD_<NAME>_SHAPE`` in its defines)."""
STORAGE_BINDING = 3
"""Storage-buffer binding of the tables (``binding = 3`` in the shader)."""
MAP_UNIT = 6
"""First texture unit of the roughness, metallic and specular maps (0, 1: base color, alpha; 2-5: dust)."""
MAPS = ("roughness_texture", "metallic_texture", "specular_texture")


def table_defines() -> str:
    """GLSL ``#define`` lines of each table's offset in the buffer and its shape (slowest axis first)."""
    lines, offset = [], 0
    for name in TABLES:
        table = host_tables()[name]
        lines.append(f"#define PD_{name.upper()} {offset}")
        lines.append(f"#define PD_{name.upper()}_SHAPE {', '.join(str(n) for n in table.shape)}")
        offset += table.size
    return "\n".join(lines) + "\n"


def table_values() -> np.ndarray:
    """Every table, flattened and concatenated in :data:`TABLES` order (float32)."""
    return np.concatenate([host_tables()[name].ravel() for name in TABLES]).astype(np.float32)


def _extra(obj: MeshObject, name: str) -> Any:
    return obj.material.extra.get(name, DEFAULTS[name])


def _rgb(value: Any) -> tuple[float, float, float]:
    return tuple(float(c) for c in value)[:3]  # type: ignore[return-value]


class ObjectPrincipled:
    """The Principled inputs of one object in the diffuse-color pass (its maps uploaded here)."""

    def __init__(self, ctx: Any, obj: MeshObject, resources: list[Any]) -> None:
        material = obj.material
        self.maps: list[Any] = []
        for slot in MAPS:
            texture = getattr(material, slot)
            if texture is None or obj.uvs is None:
                self.maps.append(None)
                continue
            values = np.ascontiguousarray(data_image(texture, obj.name, slot)[::-1])  # GL rows run bottom-up
            gl_texture = ctx.texture((values.shape[1], values.shape[0]), 1, values.tobytes(), dtype="f4")
            gl_texture.repeat_x = gl_texture.repeat_y = True
            resources.append(gl_texture)
            self.maps.append(gl_texture)
        coat, sheen = max(float(_extra(obj, "coat_weight")), 0.0), max(float(_extra(obj, "sheen_weight")), 0.0)
        coat_tint = _rgb(_extra(obj, "coat_tint"))
        self.values = {
            "u_pd_surface": (float(material.roughness), float(material.metallic), float(material.specular),
                             max(float(material.ior), 1e-5)),
            "u_pd_layers": (min(max(float(material.transmission), 0.0), 1.0),
                            min(max(float(_extra(obj, "subsurface_weight")), 0.0), 1.0), coat,
                            min(max(float(_extra(obj, "coat_roughness")), 0.0), 1.0)),
            "u_pd_coat": (max(float(_extra(obj, "coat_ior")), 1.0), float(any(c != 1.0 for c in coat_tint)), sheen,
                          min(max(float(_extra(obj, "sheen_roughness")), 0.0), 1.0)),
            "u_pd_spec_tint": _rgb(_extra(obj, "specular_tint")),
            "u_pd_coat_tint": coat_tint,
            "u_pd_sheen_tint": _rgb(_extra(obj, "sheen_tint")),
            "u_pd_mapped": tuple(texture is not None for texture in self.maps),
        }

    @property
    def needs_uv(self) -> bool:
        """Whether a map is read (the draw then needs the mesh's UVs)."""
        return any(texture is not None for texture in self.maps)

    def apply(self, program: Any) -> None:
        """Set this object's uniforms on ``program`` and bind its maps."""
        for name, value in self.values.items():
            program[name].value = value
        for index, texture in enumerate(self.maps):
            if texture is not None:
                texture.use(MAP_UNIT + index)
        for index, name in enumerate(("u_pd_roughness_map", "u_pd_metallic_map", "u_pd_specular_map")):
            program[name].value = MAP_UNIT + index
