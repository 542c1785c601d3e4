"""The denoiser's guides drawn on a worker thread while the path tracer samples.

A default color keypoint spends ~70 % of its wall time in Dr.Jit kernels that keep every core busy, and the
rest in phases that use one core: Mitsuba's start and scene load, the raster guides (GL context, upload, the
supersampled albedo and normals draws and their filter) and the denoiser's setup. Drawn on the path tracer's
thread, the guides add their whole time to every keypoint. :class:`GuideWorker` gives them a thread of their
own with its own headless GL context and its own upload of the scene (:class:`~hybridgen.render.raster.scene_raster.
SceneRaster`, made on that thread: a GL context is current on one thread): the context and upload are made
while Mitsuba starts, and each keypoint's guides are drawn while its samples are traced (Dr.Jit releases the
GIL inside kernels, the raster draws and readbacks release it through :mod:`hybridgen.render.raster.gl_calls`).
The guides are the same values as drawn on the caller's thread: same scene, same camera, same filter.

Used where the color producer would otherwise own a raster view for its guides alone (no labels in the run,
guides that do not follow specular surfaces through Mitsuba); a run that also renders labels shares the
labels' raster view on the caller's thread instead (one upload). An exception on the worker is raised again
by the call that waits for its result; a worker that does not answer within ``timeout`` seconds raises
:class:`~hybridgen.errors.SystemSetupError` instead of hanging.

Measured on the tabletop of tools/color_quality.py (320x240, default color, whole warm processes on 2 cores,
docs/color_quality.md session 12): 5.29 -> 5.11 s wall, median of 8 alternating pairs, the same CPU and bytes.
"""
from __future__ import annotations

from concurrent.futures import Future

import numpy as np

from ..scene.scene import Scene
from .denoise_guides import DEFAULT_FACTOR, DenoiseGuides
from .pathtrace import denoise
from .raster.gl_worker import DEFAULT_TIMEOUT_S, GLWorker
from .raster.raster_view import RasterView
from .raster.scene_raster import SceneRaster


class GuideWorker:
    """A :class:`~hybridgen.render.raster.gl_worker.GLWorker` that uploads ``scene`` to its own context (started at
    construction, in the background) and draws :class:`~hybridgen.render.denoise_guides.DenoiseGuides` of the
    keypoints handed to :meth:`submit`, in order."""

    def __init__(self, scene: Scene, timeout: float = DEFAULT_TIMEOUT_S, factor: int = DEFAULT_FACTOR) -> None:
        self._guides: DenoiseGuides | None = None  # made on the worker by the first submit (its filter width)
        self._factor = int(factor)  # the guides' supersampling (denoise_guides.py)

        def build(ctx: object) -> SceneRaster:
            return SceneRaster(scene, view=RasterView(scene, ctx=ctx))

        def release(raster: SceneRaster) -> None:
            raster.release()
            raster.view.release()

        self._worker: GLWorker[SceneRaster] | None = GLWorker(build, release, "hybridgen-guides", timeout)

    @property
    def guides(self) -> DenoiseGuides | None:
        """The guide renderer (made on the worker by the first :meth:`submit`; None before)."""
        return self._guides

    def submit(self, cam2world: np.ndarray, filter_width: float) -> Future:
        """Starts drawing the (albedo, normals) guides of one keypoint (OpenCV-axes ``cam2world``) for a color
        image of pixel filter ``filter_width`` (px, :mod:`hybridgen.render.pixel_filter`); :meth:`result` waits
        for them."""
        assert self._worker is not None, "submit after release"
        pose, width = np.array(cam2world, dtype=np.float64), float(filter_width)

        def draw(raster: SceneRaster) -> tuple[np.ndarray, np.ndarray]:
            if self._guides is None or self._guides.filter_width != width:
                self._guides = DenoiseGuides(raster.scene, self._factor, raster=raster, filter_width=width,
                                             follow_specular=False)
            return self._guides.render(pose)

        return self._worker.submit(draw)

    def prepare_denoiser(self) -> Future:
        """Queues :func:`hybridgen.render.pathtrace.denoise.warm_up` on the worker (before any keypoint's guides), so the
        denoiser's one-time setup overlaps the caller's; a failure there shows again where the denoiser runs."""
        assert self._worker is not None, "prepare_denoiser after release"
        return self._worker.submit(lambda raster: denoise.warm_up())

    def result(self, drawing: Future) -> tuple[np.ndarray, np.ndarray]:
        """The guides of a :meth:`submit` (the worker's exception raised again, a SystemSetupError if it hangs)."""
        assert self._worker is not None, "result after release"
        return self._worker.wait(drawing, "the denoising guides")

    def release(self) -> None:
        """Releases the GL resources on the worker (where its context is current) and ends the thread."""
        if self._worker is not None:
            worker, self._worker = self._worker, None
            worker.close()
