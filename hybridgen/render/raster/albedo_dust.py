"""Dust films (:attr:`hybridgen.scene.material.Material.dust`) in the albedo pass: per pixel centre the albedo
becomes ``m x albedo + sum_i share_i x dust color_i`` with the weights of :mod:`hybridgen.scene.dust` evaluated in
the fragment shader (``shaders/dust.glsl``) from the UV (v up, as stored; (0, 0) without UVs), the interpolated
world normal turned toward the camera and the view cosine - what Cycles' diffuse color pass shows of BlenderProc's
dust mix (the weighted sum of the two BSDFs' diffuse colors). Objects without active layers draw as before."""
from __future__ import annotations

from typing import Any

import numpy as np

from ...scene.dust import Dust
from ...scene.gradient_noise import random_offset
from ...scene.mesh_object import MeshObject
from ..material_textures import data_image

LAYERS = 4
"""Layers the shader applies (``DUST_LAYERS`` in shaders/dust.glsl); more stop with one line."""
TEXTURE_UNIT = 2
"""First texture unit of the layers' textures (0 and 1: base color and alpha)."""


def active_layers(obj: MeshObject) -> list[Dust]:
    """The object's dust layers that can show (strength > 0)."""
    return [layer for layer in obj.material.dust if layer.strength > 0]


def _linear(values: np.ndarray) -> np.ndarray:
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4).astype(np.float32)


class ObjectDust:
    """The GL inputs of one object's dust layers: layer uniforms and the layers' textures (uploaded here)."""

    def __init__(self, ctx: Any, obj: MeshObject, layers: list[Dust], resources: list[Any]) -> None:
        from ...errors import InputError

        if len(layers) > LAYERS:
            raise InputError(f"object '{obj.name}': material '{obj.material.name}' has {len(layers)} dust layers; "
                             f"the albedo pass draws at most {LAYERS}")
        self.layers = layers
        self.has_uv = obj.uvs is not None
        self.textures: list[Any] = []
        for layer in layers:
            if layer.texture is None:
                self.textures.append(None)
                continue
            values = data_image(layer.texture, obj.name, "dust texture", channels=3)
            values = np.ascontiguousarray((_linear(values) if layer.texture_srgb else values)[::-1])
            texture = ctx.texture((values.shape[1], values.shape[0]), 3, values.tobytes(), dtype="f4")
            texture.repeat_x = texture.repeat_y = True
            resources.append(texture)
            self.textures.append(texture)

    def apply(self, program: Any, obj: MeshObject, cam2world: np.ndarray) -> None:
        """Set the dust uniforms of ``obj`` for a draw from ``cam2world`` (and bind its textures)."""
        world_uniforms(program, obj, cam2world)
        program["u_dust_uv"].value = self.has_uv
        program["u_dust_count"].value = len(self.layers)
        rows = [(layer.strength, layer.texture_scale, float(layer.texture is not None), 0.0) for layer in self.layers]
        rows += [(0.0, 0.0, 0.0, 0.0)] * (LAYERS - len(rows))
        program["u_dust"].write(np.asarray(rows, np.float32).tobytes())
        colors = [layer.color for layer in self.layers] + [(0.0, 0.0, 0.0)] * (LAYERS - len(self.layers))
        program["u_dust_color"].write(np.asarray(colors, np.float32).tobytes())
        program["u_dust_offset"].write(np.asarray([random_offset(float(s)) for s in range(3)], np.float32).tobytes())
        for index, texture in enumerate(self.textures):
            if texture is not None:
                texture.use(TEXTURE_UNIT + index)
        program["u_dust_texture"].write(np.arange(TEXTURE_UNIT, TEXTURE_UNIT + LAYERS, dtype=np.int32).tobytes())


def world_uniforms(program: Any, obj: MeshObject, cam2world: np.ndarray) -> None:
    """The world position and normal of ``obj``'s fragments (``u_model``, ``u_normal_matrix``) and the camera
    position (``u_camera``) for a draw from ``cam2world``: the view direction of dust and diffuse color."""
    rotation = obj.local2world[:3, :3]
    program["u_model"].write(obj.local2world.T.astype(np.float32).tobytes())
    program["u_normal_matrix"].write(np.linalg.inv(rotation).astype(np.float32).tobytes())  # inverse transpose
    program["u_camera"].value = tuple(float(c) for c in cam2world[:3, 3])


def no_dust(program: Any) -> None:
    """An object drawn without dust."""
    program["u_dust_count"].value = 0
