"""Renderer-agnostic surface material: the principled BSDF values both renderers read."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .color_layer import ColorLayer
from .dust import Dust
from .material_mix import MaterialMix

TEXTURE_SLOTS = ("base_color_texture", "roughness_texture", "metallic_texture", "alpha_texture",
                 "normal_texture", "displacement_texture", "specular_texture", "emission_texture",
                 "coat_normal_texture")
"""The material's image inputs, all sampled with the mesh UVs."""
ALPHA_MODES = ("BLEND", "CLIP")


@dataclass
class Material:
    """A principled material. Colors are linear RGB(A) in [0, 1]; textures are file paths or arrays.

    ``base_color_texture`` (when set) replaces ``base_color``'s RGB and is sampled with the mesh UVs. A
    config override of ``base_color`` alone removes the texture (see
    :func:`hybridgen.config.material_config.apply_material_config`).

    PBR maps (file path or HxW[xC] uint8 array, read as data, not sRGB; the first channel of a gray map):

    - ``roughness_texture`` / ``metallic_texture`` / ``alpha_texture`` / ``specular_texture`` replace their
      value. ``specular`` is Blender 4's ``Specular IOR Level``: the dielectric reflectance at normal incidence is
      ((ior - 1) / (ior + 1))^2 x 2 x specular, so 0.5 keeps the IOR's own (4 % at Blender 4.2's default IOR 1.5;
      the same as Blender 3's ``Specular`` 0.5, whose 0.08 x specular this was before; docs/principled_bsdf.md).
    - ``emission_texture``: an sRGB color image replacing ``emission``'s RGB (as an image linked to the
      Principled BSDF's Emission input); the surface emits texture (decoded to linear) x
      ``emission_strength`` W sr^-1 m^-2 per texel.
    - ``normal_texture``: tangent-space normal map, RGB = (x, y, z) * 0.5 + 0.5 with x along the mesh's +u
      and y along +v (OpenGL convention, ambientCG's ``_NormalGL``); ``normal_y_down`` reads DirectX maps
      (green along -v, ambientCG's ``_NormalDX`` and cc0textures' older ``_Normal``) by inverting green.
    - ``coat_normal_texture``: the coat's own tangent-space normal map (Blender's Coat Normal input with a Normal
      Map node linked), same conventions as ``normal_texture`` (``normal_y_down`` reads both). Blender 4.2's coat
      bends only with it: with it unset the coat uses the surface's shading normal, not ``normal_texture``'s
      (docs/principled_bsdf.md). Used only where ``extra["coat_weight"]`` > 0 (hybridgen's Principled BSDF).
    - ``displacement_texture``: height h in 0..1; the surface is displaced by (h - 0.5) x
      ``displacement_scale`` metres along its normal. Rendered as a bump (shading normals only, the geometry
      and so the labels stay undisplaced) - what Blender's default material displacement method "Bump
      Only" does with BlenderProc's displacement node: BlenderProc (1.12) never sets a material's
      ``cycles.displacement_method``, so ambientCG / Poly Haven ``_Displacement`` maps are bumps in its
      renders too. True geometric displacement is the Displace modifier's job
      (:mod:`hybridgen.scene.displacement`, EntityManipulator ``displace``).
    - ``displacement_from_color``: ``displacement_texture`` is a color image (sRGB, a base color's) whose height is
      the Rec.709 luminance of its linear color, as Blender reads an image's Color linked to the displacement
      (:func:`hybridgen.render.material_textures.color_height`), times N.x + N.y + N.z of the world shading
      normal, as Cycles dots a scalar linked to the output's Displacement with it (a surface facing -y bumps
      inside out: :mod:`hybridgen.render.pathtrace.linked_height`); otherwise its first channel, as data.
    - ``emission_hidden_from_camera``: the emission lights the scene but the camera does not see it - camera
      rays see the surface's BSDF without emission, every other ray sees the emission alone (a black
      emitter). What BlenderProc's ``make_emissive`` builds (a Light Path "Is Camera Ray" mix), used for
      3D-FRONT ceilings and lamps (:mod:`hybridgen.render.pathtrace.camera_hidden_emission`).
    - ``alpha_mode``: "BLEND" - alpha is a fractional opacity in color, labels see the surface (BlenderProc's
      default, segmentation without ``use_alpha``); "CLIP" - alpha >= 0.5 is opaque, below it the surface is
      cut out of color, albedo and every label (Blender's alpha clip, BlenderProc's ``use_alpha``).
    - ``extra``: Blender 4.2's Principled inputs that have no field of their own (specular tint, anisotropy, coat,
      sheen, subsurface), under Blender's names in snake case with Blender's defaults and ranges
      (:mod:`hybridgen.scene.principled_inputs`, docs/principled_bsdf.md); hybridgen's own Principled BSDF renders
      them (JIT variants).
    - ``missing_files``: the diffuse textures (MTL ``map_Kd``) the mesh file names for this material that do not
      exist. Only outputs that show base color need them (:mod:`hybridgen.io.texture_needs`); setting
      ``base_color`` or ``base_color_texture`` through a config clears them.
    - ``dust``: dust films over the material, innermost first (:mod:`hybridgen.scene.dust`; BlenderProc's
      ``add_dust``); empty for none.
    - ``base_color_layers``: images blended over the base color, innermost first (:mod:`hybridgen.scene.color_layer`;
      BlenderProc's ``infuse_texture``); the base color under them is the texture, vertex colors or value above.
    - ``mixes``: other materials mixed into the surface, in order (:mod:`hybridgen.scene.material_mix`; BlenderProc's
      ``infuse_material``); the surface is a weighted sum of the materials' closures.
    """

    name: str = "default"
    base_color: tuple[float, float, float, float] = (0.8, 0.8, 0.8, 1.0)
    base_color_texture: Any = None  # path (str) or HxWx{3,4} uint8 array, sRGB encoded
    roughness: float = 0.5
    metallic: float = 0.0
    specular: float = 0.5
    emission: tuple[float, float, float] = (0.0, 0.0, 0.0)
    emission_strength: float = 0.0
    transmission: float = 0.0
    ior: float = 1.5  # Blender 4.2's Principled BSDF default (Blender 3's was 1.45)
    alpha: float = 1.0
    base_color_from_vertices: bool = False  # the object's vertex_colors are the base color (RGB)
    roughness_texture: Any = None
    metallic_texture: Any = None
    alpha_texture: Any = None
    alpha_mode: str = "BLEND"
    normal_texture: Any = None
    normal_y_down: bool = False
    displacement_texture: Any = None
    displacement_scale: float = 0.15  # metres per unit of height (Blender's Displacement node default in BlenderProc)
    displacement_from_color: bool = False  # displacement_texture's height is its color's luminance
    specular_texture: Any = None
    emission_texture: Any = None  # path or HxWx{3,4} uint8 array, sRGB encoded, like base_color_texture
    coat_normal_texture: Any = None  # tangent-space normal map of the coat (Coat Normal), as normal_texture
    emission_hidden_from_camera: bool = False
    missing_files: tuple[str, ...] = ()  # base-color files the mesh names that do not exist (texture_needs)
    extra: dict[str, Any] = field(default_factory=dict)
    dust: tuple[Dust, ...] = ()
    base_color_layers: tuple[ColorLayer, ...] = ()
    mixes: tuple[MaterialMix, ...] = ()

    @property
    def cuts_out(self) -> bool:
        """True where alpha clips surfaces out of the labels too (``alpha_mode`` CLIP with alpha below 1)."""
        return self.alpha_mode == "CLIP" and (self.alpha_texture is not None or self.alpha < 0.5)

    @property
    def uses_uvs(self) -> bool:
        """True if any texture is set (they are all sampled with the mesh UVs)."""
        return any(getattr(self, name) is not None for name in TEXTURE_SLOTS) or bool(self.base_color_layers)

    @staticmethod
    def from_trimesh_visual(visual: Any, fallback_name: str) -> "Material":
        """Build a material from a trimesh visual (ColorVisuals, or TextureVisuals with Simple/PBR material)."""
        mat = Material(name=fallback_name)
        material = getattr(visual, "material", None)
        if material is None:
            colors = getattr(visual, "main_color", None)
            if colors is not None and getattr(visual, "kind", None) is not None:
                mat.base_color = tuple(float(c) / 255.0 for c in np.asarray(colors)[:4])  # type: ignore[assignment]
            return mat
        mat.name = str(getattr(material, "name", None) or fallback_name)
        color = getattr(material, "baseColorFactor", None)
        if color is None:
            color = getattr(material, "diffuse", None)
        if color is not None:
            rgba = np.asarray(color, dtype=np.float64).ravel()
            if rgba.max(initial=0) > 1.0:
                rgba = rgba / 255.0
            rgba = np.concatenate([rgba, [1.0] * (4 - rgba.size)])[:4]
            mat.base_color = tuple(float(c) for c in rgba)  # type: ignore[assignment]
        image = getattr(material, "baseColorTexture", None)
        if image is None:
            image = getattr(material, "image", None)
        if image is not None:
            mat.base_color_texture = np.asarray(image.convert("RGBA"))
        for attr, key in (("roughnessFactor", "roughness"), ("metallicFactor", "metallic")):
            value = getattr(material, attr, None)
            if value is not None:
                setattr(mat, key, float(value))
        _gltf_maps(material, mat)
        return mat


def _gltf_maps(material: Any, mat: Material) -> None:
    """glTF PBR maps of a trimesh PBRMaterial: metallicRoughnessTexture (G roughness, B metallic, each
    multiplied by its factor only when the factor is 1 - other factors keep the value and drop the map),
    normalTexture (OpenGL convention, glTF's), alphaMode MASK -> CLIP with the base color's alpha channel as
    alpha map (BLEND likewise with BLEND), as Blender's glTF importer wires them."""
    packed = getattr(material, "metallicRoughnessTexture", None)
    if packed is not None:
        channels = np.asarray(packed.convert("RGB"))
        if mat.roughness == 1.0:
            mat.roughness_texture = np.ascontiguousarray(channels[..., 1])
        if mat.metallic == 1.0:
            mat.metallic_texture = np.ascontiguousarray(channels[..., 2])
    normal = getattr(material, "normalTexture", None)
    if normal is not None:
        mat.normal_texture = np.asarray(normal.convert("RGB"))
    mode = str(getattr(material, "alphaMode", None) or "OPAQUE").upper()
    if mode in ("MASK", "BLEND"):
        mat.alpha_mode = "CLIP" if mode == "MASK" else "BLEND"
        base = mat.base_color_texture
        if isinstance(base, np.ndarray) and base.ndim == 3 and base.shape[-1] == 4 and base[..., 3].min() < 255:
            mat.alpha_texture = np.ascontiguousarray(base[..., 3])
        mat.alpha = float(mat.base_color[3])
