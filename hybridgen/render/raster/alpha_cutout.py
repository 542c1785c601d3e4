"""Alpha cut-outs in the label passes: surfaces of ``alpha_mode: CLIP`` materials are left out of every label
where their alpha (map sampled bilinearly with the mesh UVs, repeating, or the constant) is below 0.5 - as
Cycles leaves surfaces below its film alpha threshold out of the index/depth/normal passes and BlenderProc's
segmentation with ``use_alpha`` cuts alpha-textured objects. BLEND materials (the default) stay opaque to labels.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...scene.mesh_object import MeshObject
from ..material_textures import alpha_coverage


@dataclass
class Cutout:
    """GL resources of one object's cut-out: its alpha map (None: the constant ``alpha``) and UV buffer."""

    alpha: float
    texture: Any
    uv_buffer: Any

    def resources(self) -> list[Any]:
        return [r for r in (self.texture, self.uv_buffer) if r is not None]


def upload_cutout(ctx: Any, obj: MeshObject, vertex_order: np.ndarray | None) -> Cutout | None:
    """The cut-out of ``obj`` on the GPU, or None when its material does not cut labels."""
    material = obj.material
    if not material.cuts_out:
        return None
    if material.alpha_texture is None or obj.uvs is None:
        return Cutout(float(material.alpha) if material.alpha_texture is None else 1.0, None, None)
    image = alpha_coverage(material.alpha_texture, obj.name)
    texture = ctx.texture((image.shape[1], image.shape[0]), 1, image.tobytes())
    texture.repeat_x = texture.repeat_y = True
    uvs = np.asarray(obj.uvs, dtype=np.float32)
    uv_buffer = ctx.buffer(np.ascontiguousarray(uvs if vertex_order is None else uvs[vertex_order]).tobytes())
    return Cutout(1.0, texture, uv_buffer)


def set_cutout_uniforms(program: Any, cutout: Cutout, unit: int = 0) -> None:
    """Uniforms of the label program's cut-out variant (``ALPHA_CUTOUT`` defined) for one draw; objects
    without a cut-out are drawn by the plain variant, which keeps every fragment."""
    program["u_alpha_mapped"].value = cutout.texture is not None
    program["u_alpha"].value = cutout.alpha
    if cutout.texture is not None:
        cutout.texture.use(unit)
        program["u_alpha_texture"].value = unit
