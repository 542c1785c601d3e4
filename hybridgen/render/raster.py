"""The raster view: exact per-pixel-centre labels of a scene with moderngl (one MRT pass per keypoint).

Geometry is uploaded once when the view is built; each keypoint only changes uniforms. Back faces are
culled for an object only where that cannot change a label: the mesh is a closed, outward-wound volume and
the camera (with its near plane) is outside its bounding box, so the first surface every ray meets is a
front face.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable

import numpy as np

from ..errors import InputError
from ..scene.camera import Intrinsics
from ..scene.scene import Scene
from .gl_context import shared_context
from .passes import PASSES, RasterOutput
from .projection import near_plane_corner_distance, projection_from_K
from .shader_source import shader_source

NORMAL_SPACES = ("camera", "world")


@dataclass
class GpuObject:
    """GL resources of one scene object (vertex positions and indices are shared with other passes)."""

    instance_id: int
    vao: Any
    positions: Any
    indices: Any
    buffers: list[Any]
    face_normals: Any
    smooth: bool
    closed: bool
    bounds: np.ndarray  # (2, 3) local box
    local2world: np.ndarray


class RasterView:
    """Renders label passes of ``scene`` for any keypoint of its camera.

    ``normals_space`` is "camera" (OpenCV axes) or "world"; ``depth_background`` fills pixels that hit
    nothing in ``depth`` and ``distance``. Poses of objects are read from the scene at every render, so
    moving an object costs nothing; changing its geometry needs a new view.
    """

    def __init__(self, scene: Scene, *, normals_space: str = "camera", depth_background: float = float("inf"),
                 device_index: int | None = None, ctx: Any = None) -> None:
        if normals_space not in NORMAL_SPACES:
            raise InputError(f"normals_space must be one of {NORMAL_SPACES}, got {normals_space!r}")
        self.scene = scene
        self.normals_space = normals_space
        self.depth_background = float(depth_background)
        self.ctx = ctx if ctx is not None else shared_context(device_index)
        self.program = self.ctx.program(vertex_shader=shader_source("labels.vert"),
                                        fragment_shader=shader_source("labels.frag"))
        self.gpu_objects = [self._upload(obj) for obj in scene.objects]
        try:  # instance id -> category_id, for the category_id_segmaps pass (0 where an object has none)
            self._class_lut = self.category_lut()
        except InputError:
            self._class_lut = np.zeros(len(scene.objects) + 1, dtype=np.int32)
        self._fbo: Any = None
        self._fbo_size: tuple[int, int] | None = None
        self._ray_lengths: np.ndarray | None = None
        self._ray_key: Any = None

    # ----------------------------------------------------------------- resources
    def _upload(self, obj: Any) -> GpuObject:
        ctx = self.ctx
        positions = ctx.buffer(obj.vertices.astype(np.float32).tobytes())
        indices = ctx.buffer(obj.faces.astype(np.uint32).tobytes())
        face_normals = ctx.buffer(obj.face_normals.astype(np.float32).tobytes())
        content = [(positions, "3f", "in_position")]
        buffers = [positions, indices]
        smooth = obj.vertex_normals is not None
        if smooth:
            normals = ctx.buffer(obj.vertex_normals.astype(np.float32).tobytes())
            content.append((normals, "3f", "in_normal"))
            buffers.append(normals)
        vao = ctx.vertex_array(self.program, content, index_buffer=indices, index_element_size=4)
        return GpuObject(obj.instance_id, vao, positions, indices, buffers, face_normals, smooth,
                         obj.is_closed, obj.bounds_local, obj.local2world)

    def _framebuffer(self, width: int, height: int) -> Any:
        if self._fbo_size != (width, height):
            if self._fbo is not None:
                for attachment in (*self._fbo.color_attachments, self._fbo.depth_attachment):
                    attachment.release()
                self._fbo.release()
            ctx = self.ctx
            self._fbo = ctx.framebuffer(
                color_attachments=[ctx.renderbuffer((width, height), 4, dtype="f4"),
                                   ctx.renderbuffer((width, height), 1, dtype="u4")],
                depth_attachment=ctx.depth_renderbuffer((width, height)))
            self._fbo_size = (width, height)
        return self._fbo

    def _rays(self, intr: Intrinsics) -> np.ndarray:
        key = (intr.K.tobytes(), intr.width, intr.height)
        if self._ray_key != key:
            self._ray_lengths = np.linalg.norm(intr.pixel_rays(), axis=-1).astype(np.float32)
            self._ray_key = key
        assert self._ray_lengths is not None
        return self._ray_lengths

    def category_lut(self, attribute: str = "category_id") -> np.ndarray:
        """int32 table: instance id -> the object's numeric ``attribute`` (category_id or a custom one)."""
        lut = np.zeros(max((o.instance_id for o in self.scene.objects), default=0) + 1, dtype=np.int32)
        for obj in self.scene.objects:
            value = obj.category_id if attribute == "category_id" else obj.attributes.get(attribute)
            if value is None or isinstance(value, bool) or not isinstance(value, (int, float, np.integer)):
                raise InputError(f"object '{obj.name}' has no numeric '{attribute}' to map segmentation by")
            lut[obj.instance_id] = int(value)
        return lut

    # ----------------------------------------------------------------- rendering
    def render_raw(self, cam2world: np.ndarray, intrinsics: Intrinsics | None = None,
                   hidden: frozenset[int] = frozenset()) -> RasterOutput:
        """Draw one keypoint (OpenCV-axes ``cam2world``) and read back normals+depth and instance ids.

        Objects whose instance id is in ``hidden`` are left out (rays pass through them).
        """
        intr = intrinsics or self.scene.camera.intrinsics
        width, height = intr.width, intr.height
        fbo = self._framebuffer(width, height)
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(self.ctx.DEPTH_TEST)
        cam2world = np.asarray(cam2world, dtype=np.float64)
        world2cam = np.linalg.inv(cam2world)
        prog = self.program
        prog["u_projection"].write(projection_from_K(intr.K, width, height, intr.clip_start, intr.clip_end)
                                   .T.astype(np.float32).tobytes())
        to_output = np.eye(3) if self.normals_space == "camera" else cam2world[:3, :3]
        prog["u_cam_to_output"].write(to_output.T.astype(np.float32).tobytes())
        near_reach = near_plane_corner_distance(intr.K, width, height, intr.clip_start)
        cam_pos = cam2world[:3, 3]
        for gpu, obj in zip(self.gpu_objects, self.scene.objects):
            if gpu.instance_id in hidden:
                continue
            modelview = world2cam @ obj.local2world
            linear = modelview[:3, :3]
            det = np.linalg.det(linear)
            if det == 0:
                continue  # zero scale: nothing to draw
            normal_to_cam = np.linalg.inv(linear).T
            prog["u_modelview"].write(modelview.T.astype(np.float32).tobytes())
            prog["u_normal_to_cam"].write(normal_to_cam.T.astype(np.float32).tobytes())
            prog["u_smooth"].value = gpu.smooth
            prog["u_instance_id"].value = gpu.instance_id
            if gpu.closed and _outside_box(cam_pos, obj.local2world, gpu.bounds, near_reach):
                self.ctx.enable(self.ctx.CULL_FACE)
                # The projection mirrors handedness, and so does a mirroring object transform.
                self.ctx.front_face = "cw" if det > 0 else "ccw"
            else:
                self.ctx.disable(self.ctx.CULL_FACE)
            gpu.face_normals.bind_to_storage_buffer(0)
            gpu.vao.render()
        normal_depth = np.empty((height, width, 4), dtype=np.float32)
        instance = np.empty((height, width), dtype=np.uint32)
        fbo.read_into(normal_depth, attachment=0, components=4, dtype="f4")
        fbo.read_into(instance, attachment=1, components=1, dtype="u4")
        return RasterOutput(normal_depth, instance, self._rays(intr), self._class_lut, self.depth_background)

    def render(self, cam2world: np.ndarray, passes: Iterable[str] = ("depth", "normals", "instance_segmaps"),
               intrinsics: Intrinsics | None = None) -> dict[str, np.ndarray]:
        """Render one keypoint and return the requested passes (keys of :data:`PASSES`) by name."""
        names = list(passes)
        unknown = [n for n in names if n not in PASSES]
        if unknown:
            raise InputError(f"unknown label pass(es) {unknown}; known: {sorted(PASSES)}")
        raw = self.render_raw(cam2world, intrinsics)
        return {name: PASSES[name].compute(raw) for name in names}

    def release(self) -> None:
        """Free the GL resources of this view (the context stays)."""
        for gpu in self.gpu_objects:
            gpu.vao.release()
            gpu.face_normals.release()
            for buf in gpu.buffers:
                buf.release()
        self.gpu_objects = []
        if self._fbo is not None:
            self._fbo.release()
            self._fbo = None
            self._fbo_size = None


def _outside_box(cam_pos: np.ndarray, local2world: np.ndarray, bounds: np.ndarray, margin: float) -> bool:
    """True if the camera centre is farther than ``margin`` (m, world) from the object's local box."""
    to_local = np.linalg.inv(local2world)
    p = to_local[:3, :3] @ cam_pos + to_local[:3, 3]
    # Distance in local units; convert the world margin with the largest local->world stretch bound.
    stretch = np.linalg.norm(to_local[:3, :3], ord=2)
    gap = np.maximum(np.maximum(bounds[0] - p, p - bounds[1]), 0.0)
    return bool(np.linalg.norm(gap) > margin * stretch)
