"""Infused images (:attr:`hybridgen.scene.material.Material.base_color_layers`, BlenderProc's ``infuse_texture``) in
the albedo pass: at each pixel centre the base color goes through the layers' MixRGB blends of
:mod:`hybridgen.scene.color_layer`, evaluated in the fragment shader (``shaders/color_layers.glsl``) from the UV (v
up, as stored; (0, 0) without UVs), before the diffuse-color variant and dust see it - so the denoiser's albedo
guide and the ``diffuse`` output show the infused image as the path tracer does. Objects without layers draw their
base color as before."""
from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import InputError
from ...scene.mesh_object import MeshObject
from ..material_textures import data_image
from ..tonemap import srgb_decode

LAYERS = 4
"""Layers the shader applies (``COLOR_LAYER_COUNT`` in shaders/color_layers.glsl); more stop with one line."""
TEXTURE_UNIT = 9
"""First texture unit of the layers' images (0, 1: base color and alpha; 2-5: dust; 6-8: diffuse color's maps)."""


class ObjectLayers:
    """The GL inputs of one object's infused images: per-layer uniforms and the images (uploaded here, linear
    float RGB, bottom-up rows, repeating)."""

    def __init__(self, ctx: Any, obj: MeshObject, resources: list[Any]) -> None:
        layers = obj.material.base_color_layers
        if len(layers) > LAYERS:
            raise InputError(f"object '{obj.name}': material '{obj.material.name}' has {len(layers)} infused "
                             f"textures; the albedo pass draws at most {LAYERS}")
        self.has_uv = obj.uvs is not None
        self.rows = [(layer.clamped_factor, layer.uv_scale, float(layer.blend == "OVERLAY"), float(layer.invert))
                     for layer in layers]
        self.rows += [(0.0, 0.0, 0.0, 0.0)] * (LAYERS - len(self.rows))
        self.count = len(layers)
        self.textures = []
        for layer in layers:
            values = data_image(layer.texture, obj.name, "infused texture", channels=3)
            if layer.texture_srgb:
                values = srgb_decode(values)
            values = np.ascontiguousarray(values[::-1], dtype=np.float32)
            texture = ctx.texture((values.shape[1], values.shape[0]), 3, values.tobytes(), dtype="f4")
            texture.repeat_x = texture.repeat_y = True
            resources.append(texture)
            self.textures.append(texture)

    def apply(self, program: Any) -> None:
        """Set this object's layer uniforms (and bind its images) for a draw."""
        program["u_layer_uv"].value = self.has_uv
        program["u_layer_count"].value = self.count
        program["u_layer"].write(np.asarray(self.rows, np.float32).tobytes())
        for index, texture in enumerate(self.textures):
            texture.use(TEXTURE_UNIT + index)
        program["u_layer_texture"].write(np.arange(TEXTURE_UNIT, TEXTURE_UNIT + LAYERS, dtype=np.int32).tobytes())


def no_layers(program: Any) -> None:
    """An object drawn with its base color as it is."""
    program["u_layer_count"].value = 0
