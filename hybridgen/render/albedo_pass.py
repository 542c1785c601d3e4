"""Diffuse albedo of every pixel centre from the raster view (linear RGB, float32 H x W x 3).

The guide image for denoising, and a label of its own: the material's base color, or its base-color
texture (decoded from sRGB, bilinear, repeating, as Mitsuba samples it) at the surface point seen through
the pixel centre. Background pixels get ``background`` (by default the world color). Textures and UVs are
uploaded on first use only.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..scene.camera import Intrinsics
from ..scene.mesh_object import MeshObject
from .projection import projection_from_K
from .raster import RasterView
from .shader_source import shader_source

GL_SRGB8_ALPHA8 = 0x8C43


def _texture_image(obj: MeshObject) -> np.ndarray | None:
    texture = obj.material.base_color_texture
    if texture is None or obj.uvs is None:
        return None
    if isinstance(texture, (str,)):
        from PIL import Image

        from ..io.image_check import check_image_file

        check_image_file(texture, f"object '{obj.name}': texture file")
        texture = np.asarray(Image.open(texture).convert("RGBA"))
    image = np.asarray(texture)
    if image.shape[-1] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=-1)
    return np.ascontiguousarray(image[::-1])  # GL rows run bottom-up, like UV v


class AlbedoPass:
    """Draws the albedo of ``view``'s scene; shares its GL context and vertex buffers."""

    def __init__(self, view: RasterView) -> None:
        self.view = view
        ctx = view.ctx
        self.program = ctx.program(vertex_shader=shader_source("albedo.vert"),
                                   fragment_shader=shader_source("albedo.frag"))
        self._draws: list[tuple[Any, Any, MeshObject]] = []
        self._resources: list[Any] = []
        for gpu, obj in zip(view.gpu_objects, view.scene.objects):
            image = _texture_image(obj)
            texture = None
            content = [(gpu.positions, "3f", "in_position")]
            if image is not None:
                uvs = np.asarray(obj.uvs, dtype=np.float32)
                uv = ctx.buffer((uvs if gpu.vertex_order is None else uvs[gpu.vertex_order]).tobytes())
                content.append((uv, "2f", "in_uv"))
                texture = ctx.texture((image.shape[1], image.shape[0]), 4, image.tobytes(),
                                      internal_format=GL_SRGB8_ALPHA8)
                texture.repeat_x = texture.repeat_y = True
                self._resources += [uv, texture]
            vao = ctx.vertex_array(self.program, content, index_buffer=gpu.indices, index_element_size=4)
            self._resources.append(vao)
            self._draws.append((vao, texture, obj))
        self._fbos: dict[tuple[int, int], Any] = {}  # one per image size (labels, supersampled guides)

    def render(self, cam2world: np.ndarray, background: tuple[float, float, float] | None = None,
               intrinsics: Intrinsics | None = None) -> np.ndarray:
        """(H, W, 3) float32 linear albedo of one keypoint (OpenCV-axes ``cam2world``) with ``intrinsics``
        (default: the scene camera's)."""
        import moderngl

        intr = intrinsics or self.view.scene.camera.intrinsics
        ctx = self.view.ctx
        size = (intr.width, intr.height)
        if size not in self._fbos:
            self._fbos[size] = ctx.framebuffer(color_attachments=[ctx.renderbuffer(size, 4, dtype="f4")],
                                               depth_attachment=ctx.depth_renderbuffer(size))
        fbo = self._fbos[size]
        bg = background if background is not None else self.view.scene.world.color
        fbo.use()
        fbo.clear(float(bg[0]), float(bg[1]), float(bg[2]), 1.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.disable(moderngl.CULL_FACE)
        world2cam = np.linalg.inv(cam2world)
        self.program["u_projection"].write(projection_from_K(intr.K, intr.width, intr.height, intr.clip_start,
                                                             intr.clip_end).T.astype(np.float32).tobytes())
        for vao, texture, obj in self._draws:
            self.program["u_modelview"].write((world2cam @ obj.local2world).T.astype(np.float32).tobytes())
            self.program["u_base_color"].value = tuple(float(c) for c in obj.material.base_color)
            self.program["u_textured"].value = texture is not None
            if texture is not None:
                texture.use(0)
                self.program["u_texture"].value = 0
            vao.render()
        out = np.empty((intr.height, intr.width, 4), dtype=np.float32)
        fbo.read_into(out, components=4, dtype="f4")
        return np.ascontiguousarray(out[..., :3])

    def release(self) -> None:
        for resource in self._resources:
            resource.release()
        self._resources = []
        if self.program is not None:
            self.program.release()
            self.program = None
        for fbo in self._fbos.values():
            for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                attachment.release()
            fbo.release()
        self._fbos.clear()
