"""The raster view: exact per-pixel-centre labels of a scene with moderngl (one MRT pass per keypoint).

Over 300 lines: one class owns the view's GL state from upload through draw to readback and release.

Geometry is uploaded once when the view is built; each keypoint only changes uniforms. Back faces are
culled for an object only where that cannot change a label: the mesh is a closed, outward-wound volume and
the camera (with its near plane) is outside its bounding box, so the first surface every ray meets is a
front face.

Per-object GL resources are uploaded by :mod:`.gpu_objects` and the per-object matrices of a draw computed by
:mod:`.object_poses`; every GL object (programs, buffers, vertex arrays, framebuffers) is released by
:class:`RasterView` itself, so that ``release()`` frees exactly what the view made.
"""
from __future__ import annotations

from functools import partial
from typing import Any, Iterable

import numpy as np

from ...errors import InputError
from ...scene.camera import Intrinsics
from ...scene.scene import Scene
from .alpha_cutout import set_cutout_uniforms
from .face_planes import AGREEMENT, pixel_to_ray
from .framebuffer_ring import FramebufferRing
from .gl_calls import gl_calls
from .gl_context import compile_program, shared_context, software_renderer
from .gpu_objects import GpuObject, upload_objects
from .label_framebuffers import attachments, clear_framebuffer, create_framebuffer, destroy_framebuffer
from .label_targets import LabelTargets
from .object_poses import ObjectPoses
from .projection import near_plane_corner_distance, projection_from_K
from .raster_passes import RASTER_PASSES
from .readback import RasterOutput
from .shader_source import shader_source
from .triangle_clusters import draw_commands, visible_clusters

NORMAL_SPACES = ("camera", "world")
READBACKS = ("direct", "pbo")

__all__ = ["NORMAL_SPACES", "READBACKS", "RasterView", "software_renderer"]



class RasterView:
    """Renders label passes of ``scene`` for any keypoint of its camera.

    ``normals_space`` is "camera" (OpenCV axes) or "world"; ``depth_background`` fills pixels that hit
    nothing in ``depth`` and ``distance``; ``cull_clusters``: leave out, per keypoint, the triangle clusters
    of large meshes that cannot make a fragment (render/raster/triangle_clusters.py; labels are the same without).

    ``readback``: "direct" reads each target into its array when the keypoint is collected (``glReadPixels``
    to client memory: with llvmpipe the copy out of its tiles is all the work there is); "pbo" queues the
    copies into pixel-pack buffers right after the draws, so that a GPU transfers keypoint k while keypoint
    k - 1 is processed, and collecting only maps them. Default: "direct" on software renderers (there a PBO
    adds a copy and makes the draw finish before ``submit`` returns), "pbo" on GPUs. Same values either way.

    ``exact_depth``: the label shader computes z-depth by intersecting each pixel centre's ray with its
    triangle's plane (render/raster/face_planes.py) instead of interpolating it. Default: on for GPUs, whose
    rasterizers interpolate from snapped vertex positions (off by up to ~1.5e-4 of the depth at grazing angles);
    off for software renderers, where interpolation is exact to float32 and the extra reads cost throughput.

    ``gil_free``: issue the draws and the direct readback through :mod:`hybridgen.render.raster.gl_calls` (the same
    GL calls without holding the GIL, so compressor threads and other raster threads run meanwhile); False:
    through moderngl.

    Poses of objects are read from the scene at every render, so moving an object costs nothing; changing
    its geometry needs a new view.
    """

    def __init__(self, scene: Scene, *, normals_space: str = "camera", depth_background: float = float("inf"),
                 device_index: int | None = None, ctx: Any = None, cull_clusters: bool = True,
                 readback: str | None = None, gil_free: bool = True, exact_depth: bool | None = None) -> None:
        if normals_space not in NORMAL_SPACES:
            raise InputError(f"normals_space must be one of {NORMAL_SPACES}, got {normals_space!r}")
        self.scene = scene
        self.normals_space = normals_space
        self.depth_background = float(depth_background)
        self.cull_clusters = cull_clusters  # leave out triangle clusters that make no fragment (exact)
        self.ctx = ctx if ctx is not None else shared_context(device_index)
        software = software_renderer(self.ctx)
        self.readback = readback or ("direct" if software else "pbo")
        if self.readback not in READBACKS:
            raise InputError(f"readback must be one of {READBACKS}, got {readback!r}")
        self.exact_depth = not software if exact_depth is None else bool(exact_depth)
        self._gl = gl_calls() if gil_free else None  # draws and reads that release the GIL (gl_calls.py)
        self.program = self._label_program(cutout=False)
        self._cutout_program: Any = None  # built with the first object that cuts out (render/raster/alpha_cutout.py)
        self._packed_programs: dict[tuple[LabelTargets, bool], Any] = {}  # label_targets.py variants
        # exact depth: 0, 1, 2, ... read per draw at its base instance (its first triangle), one for all objects
        self._triangle_bases = self.ctx.buffer(np.arange(max([len(obj.faces) for obj in scene.objects] + [1]),
                                                         dtype=np.uint32).tobytes()) if self.exact_depth else None
        self.gpu_objects = upload_objects(self.ctx, scene.objects, self._object_program, self._triangle_bases,
                                          cull_clusters)
        self._poses = ObjectPoses(scene.objects)
        try:  # instance id -> category_id, for the category_id_segmaps pass (0 where an object has none)
            self._class_lut = self.category_lut()
        except InputError:
            self._class_lut = np.zeros(len(scene.objects) + 1, dtype=np.int32)
        # slot -> framebuffer (and its pixel-pack buffers): a ring per image shape (render/raster/framebuffer_ring.py)
        self._framebuffers = FramebufferRing(partial(create_framebuffer, self.ctx, self.readback), destroy_framebuffer)
        self._submitted: dict[Any, tuple[Intrinsics, LabelTargets | None, bool]] = {}
        self._fences: dict[Any, int] = {}  # slot -> fence after its draws (direct GIL-free readback)
        self._ray_lengths: np.ndarray | None = None
        self._ray_key: Any = None

    # ----------------------------------------------------------------- resources
    def _label_program(self, cutout: bool, targets: LabelTargets | None = None) -> Any:
        """The label program; its cut-out variant also interpolates UVs and drops fragments of low alpha (a
        shader that may discard costs llvmpipe its early depth test and a varying for every object);
        ``targets``: the packed variant writing those targets (render/raster/label_targets.py)."""
        vertex, fragment = shader_source("labels.vert"), shader_source("labels.frag")
        if cutout:
            vertex, fragment = (text.replace("\n", "\n#define ALPHA_CUTOUT\n", 1) for text in (vertex, fragment))
        if self.exact_depth:
            defines = f"\n#define EXACT_DEPTH\n#define EXACT_DEPTH_AGREEMENT {AGREEMENT!r}\n"
            vertex, fragment = (text.replace("\n", defines, 1) for text in (vertex, fragment))
        if targets is not None:
            fragment = fragment.replace("\n", f"\n{targets.defines()}\n", 1)
        return compile_program(self.ctx, vertex_shader=vertex, fragment_shader=fragment)

    def _object_program(self, cutout: bool) -> Any:
        """The default label program, or its cut-out variant (built on first use)."""
        if not cutout:
            return self.program
        if self._cutout_program is None:
            self._cutout_program = self._label_program(cutout=True)
        return self._cutout_program

    def _programs(self) -> list[Any]:
        return [p for p in (self.program, self._cutout_program, *self._packed_programs.values()) if p is not None]

    def _draw_program(self, gpu: GpuObject, targets: LabelTargets | None) -> tuple[Any, Any]:
        """(program, vertex array) drawing ``gpu`` into ``targets`` (None: the default targets); the packed
        variants and their vertex arrays are built on first use."""
        cutout = gpu.cutout is not None
        if targets is None:
            return (self._cutout_program if cutout else self.program), gpu.vao
        key = (targets, cutout)
        if key not in self._packed_programs:
            self._packed_programs[key] = self._label_program(cutout, targets)
        program = self._packed_programs[key]
        if key not in gpu.packed_vaos:  # attributes a variant does not read (normals) are left out
            content = [entry for entry in gpu.content if entry[2] in program]
            gpu.packed_vaos[key] = self.ctx.vertex_array(program, content, index_buffer=gpu.indices,
                                                         index_element_size=4)
        return program, gpu.packed_vaos[key]

    def _drop_fence(self, slot: Any) -> None:
        """Forget the fence of ``slot``'s previous draws (never collected)."""
        fence = self._fences.pop(slot, None)
        if fence is not None and self._gl is not None:
            self._gl.discard(fence)

    def _rays(self, intr: Intrinsics) -> np.ndarray:
        key = (intr.K.tobytes(), intr.width, intr.height)
        if self._ray_key != key:
            self._ray_lengths = intr.pixel_ray_lengths()
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
                   hidden: frozenset[int] = frozenset(), normals_space: str | None = None,
                   targets: LabelTargets | None = None) -> RasterOutput:
        """Draw one keypoint (OpenCV-axes ``cam2world``) and read back normals+depth and instance ids (or, with
        ``targets``, the packed targets of :mod:`hybridgen.render.raster.label_targets`).

        Objects whose instance id is in ``hidden`` are left out (rays pass through them). ``intrinsics``
        (default: the scene camera's) and ``normals_space`` (default: the view's) may differ per call: one
        view serves labels, amodal silhouettes on a wider canvas and supersampled denoising guides, keeping a
        framebuffer per image size.
        """
        intr = intrinsics or self.scene.camera.intrinsics
        slot = ("now", intr.width, intr.height)
        self.submit(cam2world, intr, hidden, slot=slot, normals_space=normals_space, targets=targets)
        return self.collect(slot)

    def submit(self, cam2world: np.ndarray, intrinsics: Intrinsics | None = None,
               hidden: frozenset[int] = frozenset(), slot: Any = 0, normals_space: str | None = None,
               region: tuple[int, int, int, int] | None = None, targets: LabelTargets | None = None) -> None:
        """Issue the draws of one keypoint into framebuffer ``slot`` without waiting for them.

        The rasterizer (llvmpipe's threads, or the GPU) works on it while the caller goes on - e.g. turning
        the previous keypoint's readback into passes; :meth:`collect` then reads it back. Two slots give a
        two-deep pipeline. ``region`` ``(x, y, width, height)`` in pixels limits clearing and drawing to that
        rectangle (a scissor: pixels inside it get exactly the values of a full draw, the rest is stale).
        ``targets``: write the packed targets (:mod:`hybridgen.render.raster.label_targets`) instead of the default.
        """
        intr = intrinsics or self.scene.camera.intrinsics
        width, height = intr.width, intr.height
        self._drop_fence(slot)
        fbo, pbos = self._framebuffers.resources(self._framebuffers.bind(slot, (width, height, targets)))
        fbo.scissor = region
        fbo.use()
        clear_framebuffer(fbo, targets, self.depth_background)
        self.ctx.enable(self.ctx.DEPTH_TEST)
        cam2world = np.asarray(cam2world, dtype=np.float64)
        world2cam = np.eye(4)
        world2cam[:3, :3] = cam2world[:3, :3].T
        world2cam[:3, 3] = -cam2world[:3, :3].T @ cam2world[:3, 3]
        projection = projection_from_K(intr.K, width, height, intr.clip_start, intr.clip_end).T.astype(np.float32)
        to_output = np.eye(3) if (normals_space or self.normals_space) == "camera" else cam2world[:3, :3]
        near_reach = near_plane_corner_distance(intr.K, width, height, intr.clip_start)
        draws = [(*self._draw_program(draw[0], targets), *draw)
                 for draw in self._poses.draws(self.gpu_objects, cam2world, world2cam, near_reach, hidden)]
        frame_uniforms = {"u_projection": projection.tobytes(),
                          "u_cam_to_output": to_output.T.astype(np.float32).tobytes(),
                          "u_pixel_to_ray": pixel_to_ray(intr.K).tobytes()}
        programs = {id(draw[0]): draw[0] for draw in draws}  # the few distinct programs of this keypoint
        members = {key: set(program) for key, program in programs.items()}  # their uniform names, once each
        for key, program in programs.items():
            for name, value in frame_uniforms.items():
                if name in members[key]:  # a packed variant without normals has no normal uniforms
                    program[name].write(value)
        for prog, vao, gpu, modelview, normal_to_cam, cull, front_face, placement in draws:
            commands = None
            if gpu.clusters is not None:  # leave out the clusters that cannot make a fragment
                keep = visible_clusters(gpu.clusters, placement[0], intr.K, width, height, intr.clip_start,
                                        intr.clip_end, placement[1] if cull else None)
                if not keep.any():
                    continue
                if not keep.all():
                    commands = draw_commands(gpu.clusters, keep)
            prog["u_modelview"].write(modelview)
            if "u_normal_to_cam" in members[id(prog)]:
                prog["u_normal_to_cam"].write(normal_to_cam)
            prog["u_instance_id"].value = gpu.instance_id
            if targets is not None and targets.category_dtype is not None:
                prog["u_category_id"].value = int(self._class_lut[gpu.instance_id])
            if gpu.cutout is not None:
                set_cutout_uniforms(prog, gpu.cutout)
            if gpu.planes is not None:
                gpu.planes.bind_to_storage_buffer(0)
            # The projection mirrors handedness (and so may the object's transform): front_face is set so
            # that gl_FrontFacing means "the side the normal points to faces the camera".
            self.ctx.front_face = front_face
            if cull:
                self.ctx.enable(self.ctx.CULL_FACE)
            else:
                self.ctx.disable(self.ctx.CULL_FACE)
            if commands is not None:
                gpu.indirect.write(commands.tobytes())
            if self._gl is None:
                vao.render() if commands is None else vao.render_indirect(gpu.indirect, count=len(commands))
            elif commands is None:  # the same calls without holding the GIL (render/raster/gl_calls.py)
                self._gl.draw(prog, vao)
            else:
                self._gl.draw_indirect(prog, vao, gpu.indirect, len(commands))
        queued = self.readback == "pbo" and region is None
        if queued:  # the copies run on the GPU after the draws; collect() maps them
            for attachment, ((_, components, kind), pbo) in enumerate(zip(attachments(targets), pbos)):
                fbo.read_into(pbo, attachment=attachment, components=components, dtype=kind)
        elif self._gl is not None and region is None:  # flushes: the rasterizer starts on this keypoint now
            self._fences[slot] = self._gl.fence()
        self._submitted[slot] = (intr, targets, queued)

    def collect(self, slot: Any = 0) -> RasterOutput:
        """Read back what :meth:`submit` drew into ``slot`` (waits for it to finish); every target is read
        straight into its own fresh contiguous array.

        With direct GIL-free readback, while another slot is in flight: wait for this slot's fence alone, then
        begin the scene of the next keypoint of this size by clearing its framebuffer, so that the read waits
        for nothing else (llvmpipe; see render/raster/framebuffer_ring.py)."""
        intr, targets, queued = self._submitted.pop(slot)
        width, height = intr.width, intr.height
        fence = self._fences.pop(slot, None)
        if fence is not None and self._gl is not None:
            self._gl.wait(fence)
            if self._submitted:
                upcoming, _ = self._framebuffers.resources(self._framebuffers.upcoming((width, height, targets)))
                upcoming.scissor = None
                upcoming.use()
                clear_framebuffer(upcoming, targets, self.depth_background)
        fbo, pbos = self._framebuffers.resources(self._framebuffers.unbind(slot))
        arrays = {name: np.empty((height, width, components) if components > 1 else (height, width), np.dtype(kind))
                  for name, components, kind in attachments(targets)}
        for attachment, (name, components, kind) in enumerate(attachments(targets)):
            if queued:
                pbos[attachment].read_into(arrays[name])
            elif self._gl is not None:  # waits for the rasterizer without holding the GIL
                self._gl.read_into(arrays[name], fbo, attachment, components, kind)
            else:
                fbo.read_into(arrays[name], attachment=attachment, components=components, dtype=kind)
        if targets is not None:
            return RasterOutput(None, arrays["instance"], partial(self._rays, intr), self._class_lut,
                                self.depth_background, depth_image=arrays["depth"],
                                normal_codes=arrays.get("normal_codes"), category=arrays.get("category"),
                                encoded=dict(targets.encoded))
        return RasterOutput(arrays["normal_depth"], arrays["instance"], partial(self._rays, intr), self._class_lut,
                            self.depth_background)

    def render_ids(self, cam2world: np.ndarray, intrinsics: Intrinsics | None = None,
                   hidden: frozenset[int] = frozenset(), region: tuple[int, int, int, int] | None = None
                   ) -> np.ndarray:
        """Only the uint32 instance ids of one keypoint (as :meth:`render_raw`, a fifth of the readback) inside
        ``region`` (x, y, width, height; default: the whole canvas): that rectangle alone is drawn and read."""
        intr = intrinsics or self.scene.camera.intrinsics
        slot = ("now", intr.width, intr.height)
        self.submit(cam2world, intr, hidden, slot=slot, region=region)
        self._submitted.pop(slot)
        self._drop_fence(slot)
        fbo, _ = self._framebuffers.resources(self._framebuffers.unbind(slot))
        x, y, w, h = region if region is not None else (0, 0, intr.width, intr.height)
        part = np.empty((h, w), dtype=np.uint32)
        fbo.read_into(part, viewport=(x, y, w, h), attachment=1, components=1, dtype="u4")
        fbo.scissor = None
        return part

    def render(self, cam2world: np.ndarray, passes: Iterable[str] = ("depth", "normals", "instance_segmaps"),
               intrinsics: Intrinsics | None = None, normals_space: str | None = None) -> dict[str, np.ndarray]:
        """Render one keypoint and return the requested passes (keys of :data:`RASTER_PASSES`) by name."""
        names = list(passes)
        unknown = [n for n in names if n not in RASTER_PASSES]
        if unknown:
            raise InputError(f"unknown label pass(es) {unknown}; known: {sorted(RASTER_PASSES)}")
        raw = self.render_raw(cam2world, intrinsics, normals_space=normals_space)
        return {name: RASTER_PASSES[name](raw) for name in names}

    def release(self) -> None:
        """Free the GL resources of this view (the context stays)."""
        for gpu in self.gpu_objects:
            if gpu.buffers:  # shared placements own no buffers and share the first placement's vaos
                gpu.vao.release()
                for vao in gpu.packed_vaos.values():
                    vao.release()
            for buf in gpu.buffers:
                buf.release()
        self.gpu_objects = []
        if self._triangle_bases is not None:
            self._triangle_bases.release()
            self._triangle_bases = None
        for slot in list(self._fences):
            self._drop_fence(slot)
        self._submitted.clear()
        self._framebuffers.release()
        for program in self._programs():  # compiled programs per view: leaked ~1.7 MB per scene before
            program.release()
        self.program = self._cutout_program = None
        self._packed_programs.clear()
