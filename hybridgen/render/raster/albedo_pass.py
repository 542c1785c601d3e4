"""Diffuse albedo of every pixel centre from the raster view (linear RGB, float32 H x W x 3).

The guide image for denoising, and a label of its own: the material's base color, or its base-color
texture (decoded from sRGB, bilinear, repeating, as Mitsuba samples it) or the interpolated per-vertex
colors at the surface point seen through the pixel centre; surfaces of alpha-clipped materials are cut out
where their alpha is below 0.5; infused images blend over the base color (:mod:`.albedo_layers`); dust films mix
in their colors by their weights (:mod:`.albedo_dust`).
Background pixels get ``background`` (by default the world color). The ``diffuse_color`` variant draws Cycles'
Diffuse Color pass instead of the base color (:mod:`.principled_diffuse`); the plain pass is unchanged by it.
Textures and UVs are uploaded on first use only.
"""
from __future__ import annotations

import copy
from typing import Any

import numpy as np

from ...scene.camera import Intrinsics
from ...scene.material_mix import components
from ...scene.mesh_object import MeshObject
from .gl_context import compile_program
from ..material_textures import alpha_coverage
from .projection import projection_from_K
from .raster_view import RasterView
from .shader_source import shader_source
from .albedo_dust import ObjectDust, active_layers, no_dust, world_uniforms
from .albedo_layers import ObjectLayers, no_layers
from . import principled_diffuse
from .label_framebuffers import release_framebuffer

GL_SRGB8_ALPHA8 = 0x8C43


def surface_parts(obj: MeshObject) -> list[tuple[MeshObject, float]]:
    """``obj`` alone (weight 1), or for a material with others mixed in (:mod:`hybridgen.scene.material_mix`) a
    shallow copy of ``obj`` per mixed material with its weight - the object's own surface first, kept even at weight
    0 (it draws the depth the others are added at)."""
    if not obj.material.mixes:
        return [(obj, 1.0)]
    parts = []
    for index, (material, weight) in enumerate(components(obj.material)):
        if weight > 0 or index == 0:
            twin = copy.copy(obj)
            twin.material = material
            parts.append((twin, weight))
    return parts


def _texture_image(obj: MeshObject) -> np.ndarray | None:
    texture = obj.material.base_color_texture
    if texture is None or obj.uvs is None:
        return None
    if isinstance(texture, (str,)):
        from PIL import Image

        from ...io.image_check import check_image_file

        check_image_file(texture, f"object '{obj.name}': texture file")
        texture = np.asarray(Image.open(texture).convert("RGBA"))
    image = np.asarray(texture)
    if image.shape[-1] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=-1)
    return np.ascontiguousarray(image[::-1])  # GL rows run bottom-up, like UV v


def _alpha_image(obj: MeshObject) -> np.ndarray | None:
    """The bottom-up uint8 alpha map of a CLIP material (None otherwise, or without UVs)."""
    material = obj.material
    if material.alpha_mode != "CLIP" or material.alpha_texture is None or obj.uvs is None:
        return None
    return alpha_coverage(material.alpha_texture, obj.name)


class AlbedoPass:
    """Draws the albedo of ``view``'s scene (with ``diffuse_color``: Cycles' Diffuse Color pass); shares the
    view's GL context and vertex buffers."""

    def __init__(self, view: RasterView, diffuse_color: bool = False) -> None:
        self.view = view
        ctx = view.ctx
        fragment = shader_source("albedo.frag").replace("// dust.glsl", shader_source("dust.glsl"))
        if any(active_layers(obj) for obj in view.scene.objects):  # the dust code only where it can show
            fragment = fragment.replace("\n", "\n#define DUST_FILMS\n", 1)
        if any(obj.material.base_color_layers for obj in view.scene.objects):  # infused images (albedo_layers.py)
            fragment = fragment.replace("\n", "\n#define COLOR_LAYERS\n", 1)
            fragment = fragment.replace("// color_layers.glsl", shader_source("color_layers.glsl"))
        self._tables = None  # the Principled tables' storage buffer (diffuse color only)
        if diffuse_color:
            fragment = fragment.replace("\n", "\n#define PRINCIPLED_DIFFUSE\n" + principled_diffuse.table_defines(), 1)
            fragment = fragment.replace("// principled_diffuse.glsl", shader_source("principled_diffuse.glsl"))
            self._tables = ctx.buffer(principled_diffuse.table_values().tobytes())
        self.program = compile_program(ctx, vertex_shader=shader_source("albedo.vert"), fragment_shader=fragment)
        self._draws: list[tuple[Any, Any, Any, MeshObject, float, bool]] = []  # vao, texture, alpha, obj, weight, first
        self._dust: dict[int, ObjectDust] = {}  # draw index -> its dust layers (render/raster/albedo_dust.py)
        self._principled: dict[int, principled_diffuse.ObjectPrincipled] = {}  # draw index -> its inputs
        self._layers: dict[int, ObjectLayers] = {}  # draw index -> its infused images
        self._resources: list[Any] = [] if self._tables is None else [self._tables]
        for gpu, obj in zip(view.gpu_objects, view.scene.objects):
            parts = surface_parts(obj)  # (object with one material, weight): materials mixed in are drawn added
            content = [(gpu.positions, "3f", "in_position")]

            def per_vertex(values: np.ndarray, layout: str, name: str) -> None:
                buffer = ctx.buffer(np.ascontiguousarray(
                    values if gpu.vertex_order is None else values[gpu.vertex_order], dtype=np.float32).tobytes())
                content.append((buffer, layout, name))
                self._resources.append(buffer)

            draws, needs_uv, needs_normal, colored = [], False, False, False
            for part, weight in parts:
                index = len(self._draws) + len(draws)
                image, alpha_image, layers = _texture_image(part), _alpha_image(part), active_layers(part)
                inputs = principled_diffuse.ObjectPrincipled(ctx, part, self._resources) if diffuse_color else None
                needs_uv |= bool(image is not None or alpha_image is not None or layers or
                                 part.material.base_color_layers or (inputs and inputs.needs_uv))
                needs_normal |= bool(layers or inputs)
                colored |= obj.vertex_colors is not None and part.material.base_color_from_vertices
                if layers:
                    self._dust[index] = ObjectDust(ctx, part, layers, self._resources)
                if inputs:
                    self._principled[index] = inputs
                if part.material.base_color_layers:
                    self._layers[index] = ObjectLayers(ctx, part, self._resources)
                texture = self._texture(image, 4, GL_SRGB8_ALPHA8)
                draws.append((texture, self._texture(alpha_image, 1), part, weight))
            if needs_uv and obj.uvs is not None:
                per_vertex(np.asarray(obj.uvs), "2f", "in_uv")
            if needs_normal:
                content.extend(entry for entry in gpu.content if entry[2] == "in_normal")
            if colored:
                per_vertex(obj.vertex_colors, "3f", "in_color")
            vao = ctx.vertex_array(self.program, content, index_buffer=gpu.indices, index_element_size=4)
            self._resources.append(vao)
            self._draws.extend((vao, texture, alpha, part, weight, position == 0)
                               for position, (texture, alpha, part, weight) in enumerate(draws))
        self._fbos: dict[tuple[int, int], Any] = {}  # one per image size (labels, supersampled guides)

    def _texture(self, image: np.ndarray | None, channels: int, internal_format: int | None = None) -> Any:
        """A repeating GL texture of a bottom-up uint8 image (None for none), released with the pass."""
        if image is None:
            return None
        extra = {} if internal_format is None else {"internal_format": internal_format}
        texture = self.view.ctx.texture((image.shape[1], image.shape[0]), channels, image.tobytes(), **extra)
        texture.repeat_x = texture.repeat_y = True
        self._resources.append(texture)
        return texture

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
        if self._tables is not None:
            self._tables.bind_to_storage_buffer(principled_diffuse.STORAGE_BINDING)
        self.program["u_projection"].write(projection_from_K(intr.K, intr.width, intr.height, intr.clip_start,
                                                             intr.clip_end).T.astype(np.float32).tobytes())
        for index, (vao, texture, alpha, obj, weight, first) in enumerate(self._draws):
            material = obj.material
            if first:  # an object's own surface: drawn over what is behind, its depth kept
                ctx.disable(moderngl.BLEND)
                ctx.depth_func = "<"
            else:  # a material mixed into it: added where the object's surface is
                ctx.enable(moderngl.BLEND)
                ctx.blend_func = moderngl.ONE, moderngl.ONE
                ctx.depth_func = "=="
            self.program["u_weight"].value = float(weight)
            if index in self._dust:
                self._dust[index].apply(self.program, obj, cam2world)
            elif self._dust:
                no_dust(self.program)
            if index in self._layers:
                self._layers[index].apply(self.program)
            elif self._layers:
                no_layers(self.program)
            if index in self._principled:
                world_uniforms(self.program, obj, cam2world)
                self._principled[index].apply(self.program)
            self.program["u_modelview"].write((world2cam @ obj.local2world).T.astype(np.float32).tobytes())
            self.program["u_base_color"].value = tuple(float(c) for c in material.base_color)
            self.program["u_textured"].value = texture is not None
            self.program["u_vertex_colored"].value = obj.vertex_colors is not None and \
                material.base_color_from_vertices
            self.program["u_alpha_clip"].value = material.alpha_mode == "CLIP"
            self.program["u_alpha_mapped"].value = alpha is not None
            self.program["u_alpha"].value = float(material.alpha)
            if texture is not None:
                texture.use(0)
                self.program["u_texture"].value = 0
            if alpha is not None:
                alpha.use(1)
                self.program["u_alpha_texture"].value = 1
            vao.render()
        ctx.disable(moderngl.BLEND)
        ctx.depth_func = "<"
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
            release_framebuffer(fbo)
        self._fbos.clear()
