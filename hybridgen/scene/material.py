"""Renderer-agnostic surface material: the principled BSDF values both renderers read."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class Material:
    """A principled material. Colors are linear RGB(A) in [0, 1]; textures are file paths or arrays.

    ``base_color_texture`` (when set) replaces ``base_color``'s RGB and is sampled with the mesh UVs. A
    config override of ``base_color`` alone removes the texture (see
    :func:`hybridgen.config.material_config.apply_material_config`).
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
    ior: float = 1.45
    alpha: float = 1.0
    extra: dict[str, Any] = field(default_factory=dict)

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
        return mat
