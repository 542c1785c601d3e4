"""The denoiser's guide images, box-filtered over each pixel's footprint like the color.

The color pixel (u, v) averages radiance over ``[u - 0.5, u + 0.5] x [v - 0.5, v + 0.5]`` (a one-pixel box
filter); a guide sampled only at the pixel centre is aliased at every silhouette and texture edge, and
Open Image Denoise, told the guides are clean, follows their hard edges: measured on the tabletop scene of
tools/color_quality.py (160x120, 64 spp, against a 1024-spp reference) 40.4 dB with centre-sampled guides,
42.9 / 43.3 / 43.3 dB with 2x2 / 3x3 / 4x4 supersampled ones. So the raster view draws albedo and normals at
``factor`` times the resolution (K scaled so that sub-pixel centres tile the pixel, see
:meth:`hybridgen.scene.camera.Intrinsics.resized`) and averages ``factor x factor`` blocks. Averaged normals
are not renormalised: at a silhouette the shorter mixed vector is what the pixel sees.

With ``follow_specular`` and the color's path-trace view, sub-pixels that see sharp glass, mirrors or smooth
metal get the features of what is seen *through* them, as Cycles' denoising passes do
(:mod:`hybridgen.render.pathtrace.specular_guides`), before the same filter; all other sub-pixels keep the raster values.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..scene.camera import Intrinsics
from ..scene.scene import Scene
from .pathtrace.specular_guides import SpecularGuideTracer, can_be_specular_like
from .pixel_filter import DEFAULT_WIDTH, filter_supersampled
from .raster.scene_raster import SceneRaster

DEFAULT_FACTOR = 3
FOLLOW_SPECULAR = False
"""Whether the guides follow sharp specular surfaces by default (:mod:`hybridgen.render.pathtrace.specular_guides`). Off,
as measured with tools/bench_denoise_guides.py on the materials scene of tools/color_quality.py (160x120, the
same noisy render denoised both ways, PSNR against two 2048-spp references without their own noise): +0.06 dB
over 6 seeds (-0.12 .. +0.19), -0.05 dB (-0.94 .. +0.53) after later sampling changes, +0.21 dB with a
checker floor seen through the glass; at BlenderProc's lobe limits (glossy and transmission bounces 0) +0.22,
+0.23 and -1.98 dB (a point light's highlights on the near-specular spheres lose the sphere's normal in the
guide). Neutral on average, with outliers, for +0.07 s of guide CPU per frame."""


class DenoiseGuides:
    """Box-filtered linear albedo and camera-space normals (float32 H x W x 3 each) of ``scene``'s camera,
    drawn with ``raster`` (the scene's shared raster view, left open) or a view built here."""

    def __init__(self, scene: Scene, factor: int = DEFAULT_FACTOR, raster: SceneRaster | None = None,
                 filter_width: float = DEFAULT_WIDTH, follow_specular: bool | None = None) -> None:
        self.factor = int(factor)
        self.filter_width = float(filter_width)  # the color's pixel filter (0: box), render/pixel_filter.py
        self._own = raster is None
        self.raster = raster or SceneRaster(scene)
        self.follow_specular = FOLLOW_SPECULAR if follow_specular is None else bool(follow_specular)
        self._tracer: tuple[Any, SpecularGuideTracer] | None = None  # (the Mitsuba scene it traces, tracer)
        self.traced_subpixels = 0  # of the last render (sub-pixels whose features come from behind glass/mirrors)

    @property
    def fine(self) -> Intrinsics:
        """The supersampled camera of the current keypoint (the scene camera's intrinsics: they may change
        between keypoints)."""
        intr = self.raster.scene.camera.intrinsics
        return intr.resized(intr.width * self.factor, intr.height * self.factor)

    def _box(self, image: np.ndarray) -> np.ndarray:
        f = self.factor
        if not np.isfinite(image).all():  # a copy only where a value needs replacing
            image = np.nan_to_num(image, nan=0.0, posinf=0.0, neginf=0.0)
        if self.filter_width > 0:
            return filter_supersampled(image, f, self.filter_width)
        blocks = image.reshape(image.shape[0] // f, f, image.shape[1] // f, f, -1)
        return np.ascontiguousarray(blocks.mean(axis=(1, 3), dtype=np.float32))

    def render(self, cam2world: np.ndarray, path_view: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(albedo, normals) of one keypoint (OpenCV-axes ``cam2world``); with ``path_view`` (the color's
        :class:`~hybridgen.render.pathtrace.path_trace.PathTraceView`, JIT variants) and ``follow_specular`` they follow
        sharp specular surfaces (:mod:`hybridgen.render.pathtrace.specular_guides`)."""
        return self.filtered(self.draw(cam2world, path_view))

    def filtered(self, fine: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(albedo, normals) at the image's resolution from :meth:`draw`'s supersampled ones: NumPy only, so any
        thread may do it (the GL context's thread draws)."""
        return self._box(fine[0]), self._box(fine[1])

    def draw(self, cam2world: np.ndarray, path_view: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """The supersampled (albedo, normals) of :meth:`render`, before :meth:`filtered`."""
        tracer = self._tracer_for(path_view)
        fine = self.fine
        albedo = self.raster.albedo.render(cam2world, intrinsics=fine)
        passes = self.raster.view.render(cam2world, ["normals"] + (["instance_segmaps"] if tracer else []),
                                         intrinsics=fine, normals_space="camera")
        normals = passes["normals"]
        self.traced_subpixels = 0
        if tracer is not None:
            normals = np.array(normals, dtype=np.float32)
            self.traced_subpixels = tracer.apply(cam2world, fine, np.asarray(passes["instance_segmaps"]),
                                                 albedo, normals)
        return albedo, normals

    def _tracer_for(self, path_view: Any) -> SpecularGuideTracer | None:
        """The tracer of ``path_view``'s Mitsuba scene (rebuilt with it), or None where nothing is traced."""
        if path_view is None or not self.follow_specular:
            return None
        if not any(can_be_specular_like(o.material) for o in self.raster.scene.objects):
            return None
        from .pathtrace.mitsuba_variant import is_jit

        if not is_jit(path_view.variant):
            return None
        if self._tracer is None or self._tracer[0] is not path_view.mi_scene:
            s = path_view.settings
            self._tracer = (path_view.mi_scene, SpecularGuideTracer(
                self.raster.scene, path_view.mi_scene, s.max_bounces, s.glossy_bounces, s.transmission_bounces))
        return self._tracer[1]

    def release(self) -> None:
        self._tracer = None
        if self._own:
            self.raster.release()
