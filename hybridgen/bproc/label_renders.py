"""``bproc.renderer.render_optical_flow`` and ``render_nocs``: label images of every frame, from one labels-only
raster render of the session (:func:`hybridgen.bproc.label_scene.label_scene`, :func:`hybridgen.render_labels`).

- Optical flow (BlenderProc's ``forward_flow`` / ``backward_flow``, float32 (H, W, 2), pixels): where the surface
  point seen at a pixel centre is in the next / previous frame's image minus where it is now
  (:mod:`hybridgen.render.raster.geometry_passes`), moving with its object between keyed poses; y grows downwards
  (``blender_image_coordinate_style=False``, the default) or upwards (True, Blender's raster). 0 on the
  background and where there is no next / previous frame (Blender then sees the same pose held: no motion).
- NOCS (``nocs``, float32 (H, W, 4)): BlenderProc's NOCS material, ``0.5 p + 0.5`` of the surface point ``p`` in
  its object's local (mesh) frame, in float16 precision (BlenderProc's 16-bit EXR), alpha 1 on objects; the
  background is transparent black (0, 0, 0, 0).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from .label_scene import label_scene
from .session import SESSION
from .types import MeshObject
from .types.unsupported import fail


def _render(request: Any, stereo: bool) -> list[dict[str, Any]]:
    """The values of ``request`` for every frame of the session (visible mesh objects at their keyed poses)."""
    import hybridgen as hg

    frames = list(range(SESSION.frame_start, SESSION.frame_end))
    if not frames:
        raise InputError("No camera poses have been registered, therefore nothing can be rendered. A camera pose "
                         "can be registered via bproc.camera.add_camera_pose().")
    objects = [e for e in SESSION.entities if isinstance(e, MeshObject) and not e.is_hidden()]
    if not objects:
        raise InputError("There are no mesh-objects to render, please load an object before invoking the renderer.")
    scene, _ = label_scene(frames, objects)
    sink = hg.MemorySink()
    baseline = SESSION.camera.interocular_distance if stereo and SESSION.camera.stereo else None
    hg.render_labels(scene, [sink], request, stereo_baseline=baseline)
    return sink.frames


def render_optical_flow(output_dir: str | None = None, temp_dir: str | None = None, get_forward_flow: bool = True,
                        get_backward_flow: bool = True, blender_image_coordinate_style: bool = False,
                        forward_flow_output_file_prefix: str = "forward_flow_",
                        forward_flow_output_key: str = "forward_flow",
                        backward_flow_output_file_prefix: str = "backward_flow_",
                        backward_flow_output_key: str = "backward_flow", return_data: bool = True,
                        verbose: bool = False) -> dict[str, list[np.ndarray]]:
    """``{forward_flow_output_key: [...], backward_flow_output_key: [...]}`` (those asked for), one (H, W, 2)
    float32 image per frame (see the module documentation)."""
    import hybridgen as hg

    if not get_forward_flow and not get_backward_flow:
        raise InputError("Take the FlowRenderer Module out of the config if both forward and backward flow are set "
                         "to False!")
    if SESSION.camera.stereo:
        fail("bproc.renderer.render_optical_flow with stereo on")
    frames = _render(hg.LabelRequest(depth=False, normals=False, map_by=[], flow=True), stereo=False)
    wanted = [(key, name) for key, name, on in (("forward_flow", forward_flow_output_key, get_forward_flow),
                                                 ("backward_flow", backward_flow_output_key, get_backward_flow)) if on]
    data: dict[str, list[np.ndarray]] = {name: [] for _, name in wanted}
    for values in frames:
        for key, name in wanted:
            flow = np.array(values[key], dtype=np.float32)
            if blender_image_coordinate_style:
                flow[..., 1] *= -1
            data[name].append(flow)
    return data if return_data else {}


def render_nocs(output_dir: str | None = None, file_prefix: str = "nocs_", output_key: str = "nocs",
                return_data: bool = True, verbose: bool = False) -> dict[str, list[np.ndarray]]:
    """``{output_key: [one (H, W, 4) float32 image per frame]}`` (see the module documentation); with stereo on,
    each has a leading axis of 2."""
    import hybridgen as hg

    request = hg.LabelRequest(depth=False, normals=False, map_by=[], passes=("object_coordinates",))
    images = []
    for values in _render(request, stereo=True):
        local = np.asarray(values["object_coordinates"], dtype=np.float32)
        hit = np.all(np.isfinite(local), axis=-1)
        rgba = np.zeros(local.shape[:-1] + (4,), np.float32)
        rgba[hit, :3] = (0.5 * local[hit] + 0.5).astype(np.float16)
        rgba[hit, 3] = 1.0
        images.append(rgba)
    return {output_key: images} if return_data else {}
