"""Images blended over a base color (:attr:`hybridgen.scene.material.Material.base_color_layers`, BlenderProc's
``infuse_texture``) as a Mitsuba 3 texture, :data:`PLUGIN_NAME`: it evaluates the material's own base color (a
bitmap, the vertex colors or a value) and then each layer's MixRGB node with :func:`hybridgen.scene.color_layer.apply_layer`
- the same code the tests evaluate with NumPy. Each layer's image is a repeating bilinear bitmap read at Blender's UV
divided by the layer's texture scale (``si.uv`` with the v flip :mod:`.mitsuba_scene` applies undone, then redone
for the lookup; (0, 0) for a mesh without UVs, as Cycles reads a missing UV map).

Whatever reads the base color reads the layered one: the Lambertian ``diffuse`` BSDF of a plain material, hybridgen's
Principled BSDF and its diffuse reflectance (the ``diffuse_color`` output's path-traced counterpart). A Python
texture runs in every Mitsuba variant; in ``scalar_rgb`` it is called per lookup (slow, but the same values).
"""
from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

from ...errors import InputError
from ...input_paths import not_found, utf8_path
from ...scene.color_layer import ColorLayer, apply_layer
from ...scene.material import Material
from .dust_mix import OPS

PLUGIN_NAME = "hybridgen_color_layers"


def check_layers(material: Material, owner: str) -> None:
    """One-line errors for layers no renderer can use (a missing image)."""
    for layer in material.base_color_layers:
        if not Path(layer.texture).is_file():
            raise InputError(f"object '{owner}': material '{material.name}' infused texture: "
                             f"{not_found('texture file', layer.texture)}")


def layered(base: dict[str, Any], material: Material, owner: str, *, uvs: bool) -> dict[str, Any]:
    """The Mitsuba texture of ``material``'s base color: ``base`` (its texture dict without layers) under the
    material's layers; ``base`` itself without layers. ``uvs``: the mesh has texture coordinates."""
    import mitsuba as mi

    if not material.base_color_layers:
        return base
    check_layers(material, owner)
    register(mi.variant())
    spec = [{"blend": layer.blend, "factor": layer.clamped_factor, "uv_scale": layer.uv_scale,
             "invert": bool(layer.invert)} for layer in material.base_color_layers]
    out: dict[str, Any] = {"type": PLUGIN_NAME, "base": base, "uvs": bool(uvs), "layers": json.dumps(spec)}
    for index, layer in enumerate(material.base_color_layers):
        out[f"texture_{index}"] = {"type": "bitmap", "filename": utf8_path(Path(layer.texture)),
                                   "raw": not layer.texture_srgb, "filter_type": "bilinear", "wrap_mode": "repeat"}
    return out


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register :data:`PLUGIN_NAME` for ``variant`` (the active variant)."""
    import drjit as dr
    import mitsuba as mi

    class ColorLayers(mi.Texture):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            base = props.get("base")
            self.base = base if isinstance(base, mi.Texture) else mi.load_dict({"type": "rgb", "value": list(base)})
            self.uvs = bool(props.get("uvs", True))
            self.specs = json.loads(props.get("layers", "[]"))
            self.layers = [ColorLayer(texture="", blend=s["blend"], factor=s["factor"], invert=s["invert"])
                           for s in self.specs]
            self.textures = [props.get(f"texture_{i}") for i in range(len(self.specs))]

        def eval(self, si: Any, active: Any = True) -> Any:
            color = self.base.eval(si, active)
            rgb = (color.x, color.y, color.z)
            u, v = (si.uv.x, 1.0 - si.uv.y) if self.uvs else (mi.Float(0.0), mi.Float(0.0))
            for spec, layer, texture in zip(self.specs, self.layers, self.textures):
                lookup = mi.SurfaceInteraction3f(si)
                lookup.uv = mi.Point2f(u * spec["uv_scale"], 1.0 - v * spec["uv_scale"])
                texel = texture.eval(lookup, active)
                rgb = apply_layer(OPS, layer, rgb, (texel.x, texel.y, texel.z))
            return mi.Color3f(*rgb)

        def eval_3(self, si: Any, active: Any = True) -> Any:
            return self.eval(si, active)

        def eval_1(self, si: Any, active: Any = True) -> Any:
            return mi.luminance(self.eval(si, active))

        def mean(self) -> Any:
            rgb = (self.base.mean(),) * 3
            for layer, texture in zip(self.layers, self.textures):
                rgb = apply_layer(OPS, layer, rgb, (texture.mean(),) * 3)
            return dr.mean(mi.Float(rgb[0]) + rgb[1] + rgb[2]) / 3.0

        def is_spatially_varying(self) -> bool:
            return True

        def traverse(self, callback: Any) -> None:
            callback.put("base", self.base, mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys: Any = None) -> None:
            pass

        def to_string(self) -> str:
            return f"HybridgenColorLayers[layers={self.specs}, uvs={self.uvs}, base={self.base}]"

    mi.register_texture(PLUGIN_NAME, lambda props: ColorLayers(props))
