"""Python API: render the label passes of every keypoint of a scene into frame sinks."""
from __future__ import annotations

from typing import Any, Callable, Iterable

import numpy as np

from .._version import __version__
from ..errors import InputError
from ..io.frame_sink import FrameSink
from ..scene.scene import Scene
from .label_request import LabelRequest
from .raster import RasterView

ProgressFactory = Callable[[int, str], Any]


def camera_records(scene: Scene) -> dict[str, np.ndarray]:
    """``cam_K`` (N,3,3) and ``cam2world`` (N,4,4, OpenCV axes) of every keypoint, float64."""
    n = len(scene.camera)
    return {"cam_K": np.repeat(scene.camera.intrinsics.K[None], n, axis=0),
            "cam2world": np.stack(scene.camera.keypoints) if n else np.zeros((0, 4, 4))}


def label_attributes(request: LabelRequest) -> dict[str, Any]:
    """HDF5 attributes stating the label conventions."""
    return {"hybridgen_version": __version__, "depth_background": request.depth_background,
            "normals_space": request.normals_space}


def render_labels(scene: Scene, sinks: Iterable[FrameSink], request: LabelRequest | None = None, *,
                  default_category_id: int | None = None, view: RasterView | None = None,
                  progress: ProgressFactory | None = None) -> int:
    """Render every keypoint of ``scene.camera`` and stream the values to ``sinks``; returns the count.

    The geometry is uploaded once (or ``view`` is reused); each keypoint is one MRT draw plus readback.
    """
    request = request or LabelRequest()
    sinks = list(sinks)
    n = len(scene.camera)
    if n == 0:
        raise InputError("the camera has no keypoints: add poses (camera.CameraLoader) before rendering")
    if not scene.objects:
        raise InputError("the scene has no objects to render")
    request.check_scene(scene, default_category_id)
    own_view = view is None
    view = view or RasterView(scene, normals_space=request.normals_space,
                              depth_background=request.depth_background)
    try:
        intr = scene.camera.intrinsics
        luts = request.lookup_tables(view)
        layouts = request.layouts(intr.width, intr.height)
        for sink in sinks:
            sink.begin(n, layouts, camera_records(scene), label_attributes(request))
        bar = progress(n, "labels") if progress else None
        for index, pose in enumerate(scene.camera.keypoints):
            values = request.compute(view.render_raw(pose), luts, scene)
            for sink in sinks:
                sink.write(index, values)
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        for sink in sinks:
            sink.end()
    finally:
        if own_view:
            view.release()
    return n
