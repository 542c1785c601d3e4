"""Python API: path-traced color of every keypoint (plus, optionally, the labels) into frame sinks."""
from __future__ import annotations

from typing import Any, Iterable, Sequence

import numpy as np

from ..io.frame_sink import FrameSink, PassLayout
from ..scene.scene import Scene
from .albedo_pass import AlbedoPass
from .denoise import denoise as oidn_denoise
from .denoise import require_oidn
from .keypoint_loop import ProgressFactory, Producer, StereoProducer, run_keypoints
from .label_request import LabelRequest
from .path_trace import PathTraceSettings, PathTraceView
from .raster import RasterView
from .render_labels import LabelProducer
from .tonemap import to_srgb8


def keypoint_seed(root_seed: int, index: int, eye: int = 0) -> int:
    """The sampler seed of keypoint ``index`` (and stereo ``eye``): a pure function of the root seed."""
    return int(np.random.SeedSequence([int(root_seed), int(index), int(eye)]).generate_state(1)[0])


class ColorProducer:
    """Producer of ``colors`` (sRGB uint8, see :mod:`hybridgen.render.tonemap`) and optionally the linear
    ``colors_hdr`` (float16) from one Mitsuba scene loaded at construction.

    With ``denoise`` the linear image goes through Open Image Denoise, guided by the raster view's albedo and
    normals, before it is encoded.
    """

    def __init__(self, scene: Scene, settings: PathTraceSettings, *, seed: int = 0, variant: str | None = None,
                 hdr: bool = False, denoise: bool = False, view: PathTraceView | None = None) -> None:
        self.scene, self.settings, self.seed, self.hdr, self.denoise = scene, settings, int(seed), hdr, denoise
        self._guides: tuple[RasterView, AlbedoPass] | None = None
        if denoise:
            require_oidn()
            raster = RasterView(scene)
            self._guides = (raster, AlbedoPass(raster))
        self.view = view or PathTraceView(scene, settings, variant=variant)

    def layouts(self) -> list[PassLayout]:
        intr = self.scene.camera.intrinsics
        shape = (intr.height, intr.width, 3)
        return [PassLayout("colors", "uint8", shape)] + ([PassLayout("colors_hdr", "float16", shape)]
                                                          if self.hdr else [])

    def attributes(self) -> dict[str, Any]:
        s = self.settings
        return {"mitsuba_variant": self.view.variant, "samples": s.samples, "min_bounces": s.min_bounces,
                "max_bounces": s.max_bounces, "mitsuba_max_depth": s.max_bounces + 2,
                "color_encoding": "sRGB transfer of linear radiance clipped to [0, 1]", "denoised": self.denoise}

    def records(self) -> dict[str, np.ndarray]:
        return {}

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        linear = self.view.render(cam2world, keypoint_seed(self.seed, index, eye))
        if self._guides is not None:
            raster, albedo = self._guides
            linear = oidn_denoise(linear, albedo.render(cam2world), raster.render(cam2world, ["normals"])["normals"])
        values: dict[str, Any] = {"colors": to_srgb8(linear)}
        if self.hdr:
            values["colors_hdr"] = linear.astype(np.float16)
        return values

    def close(self) -> None:
        """Release the denoising guides' GL resources (the Mitsuba scene goes with this producer)."""
        if self._guides is not None:
            self._guides[1].release()
            self._guides[0].release()
            self._guides = None


def render_color(scene: Scene, sinks: Iterable[FrameSink], settings: PathTraceSettings | None = None, *,
                 labels: LabelRequest | None = None, seed: int = 0, variant: str | None = None,
                 hdr: bool = False, denoise: bool = False, stereo_baseline: float | None = None,
                 default_category_id: int | None = None, progress: ProgressFactory | None = None,
                 indices: Sequence[int] | None = None) -> int:
    """Color (and ``labels`` if given) of every keypoint, as left/right pairs when ``stereo_baseline`` (m)."""
    producers: list[Producer] = []
    if labels is not None:
        producers.append(LabelProducer(scene, labels, default_category_id=default_category_id))
    producers.insert(0, ColorProducer(scene, settings or PathTraceSettings(), seed=seed, variant=variant, hdr=hdr,
                                      denoise=denoise))
    if stereo_baseline is not None:
        producers = [StereoProducer(producers, stereo_baseline, scene)]
    return run_keypoints(scene, sinks, producers, progress=progress, what="color", indices=indices)
