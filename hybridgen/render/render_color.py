"""Python API: path-traced color of every keypoint (plus, optionally, the labels) into frame sinks."""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from functools import partial
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from ..io.frame_sink import FrameSink, PassLayout
from ..io.texture_needs import require_base_colors
from ..scene.object_keyframes import varies_per_keypoint
from ..scene.scene import Scene
from . import denoise_guides
from .denoise_guides import DenoiseGuides
from .edge_blend import mix_raw_on_edges
from .guide_worker import GuideWorker
from .keypoint_guides import KeypointGuides
from .keypoint_loop import Producer, ProgressFactory, StereoProducer, run_keypoints
from .passes import color_keys, layout
from .pathtrace.denoise import denoise as oidn_denoise
from .pathtrace.denoise import require_oidn
from .pathtrace.path_trace import PathTraceSettings, PathTraceView
from .pathtrace.pooled_edges import PooledEdges
from .raster.label_producer import LabelProducer
from .raster.label_request import LabelRequest
from .raster.scene_raster import SceneRaster
from .tonemap import to_srgb8


def keypoint_seed(root_seed: int, index: int, eye: int = 0) -> int:
    """The sampler seed of keypoint ``index`` (and stereo ``eye``): a pure function of the root seed."""
    return int(np.random.SeedSequence([int(root_seed), int(index), int(eye)]).generate_state(1)[0])


class ColorProducer:
    """Producer of ``colors`` (sRGB uint8, see :mod:`hybridgen.render.tonemap`) and optionally the linear
    ``colors_hdr`` (float16) from one Mitsuba scene loaded at construction.

    With ``denoise`` the linear image goes through Open Image Denoise, guided by the raster view's albedo and
    normals (filtered like the color's pixels, :mod:`hybridgen.render.denoise_guides`), before it is
    encoded; ``keep_raw`` also stores the image before denoising as ``colors_raw``
    (sRGB uint8, encoded like ``colors``). ``sample_counts`` stores the samples each pixel received
    (uint32, ``sample_counts``; constant unless adaptive sampling is on). ``encode`` turns linear RGB into the
    8-bit ``colors`` (and ``colors_raw``): the Standard sRGB view (:func:`~hybridgen.render.tonemap.to_srgb8`)
    unless given (BlenderProc runs: Blender's Filmic view, :mod:`hybridgen.render.filmic_view`); it runs on the
    encoding thread, beside the next keypoint's sampling.
    """

    def __init__(self, scene: Scene, settings: PathTraceSettings, *, seed: int = 0, variant: str | None = None,
                 hdr: bool = False, denoise: bool = False, view: PathTraceView | None = None,
                 keep_raw: bool = False, sample_counts: bool = False, raster: SceneRaster | None = None,
                 first: tuple[int, np.ndarray] | None = None,
                 encode: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        self.scene, self.settings, self.seed, self.hdr, self.denoise = scene, settings, int(seed), hdr, denoise
        self.encode = encode or to_srgb8
        self.keep_raw, self.sample_counts = keep_raw and denoise, sample_counts
        self._guides: DenoiseGuides | None = None
        self._worker: GuideWorker | None = None
        self._denoiser: ThreadPoolExecutor | None = None  # denoising and encoding, one keypoint at a time
        self._filtering: ThreadPoolExecutor | None = None  # guides filtered, their edges found, while sampling
        self._pool: PooledEdges | None | bool = None  # edge pixels' pooled samples (False: the view cannot pool)
        self._ahead: dict[tuple[int, int, bytes, float], KeypointGuides] = {}  # the worker's, of prefetched keypoints
        if denoise and raster is None and not denoise_guides.FOLLOW_SPECULAR:
            # guides of their own: drawn on a thread of their own, its GL context made while Mitsuba starts
            self._worker = GuideWorker(scene, factor=settings.guide_factor)
        try:
            if denoise:
                require_oidn()
                if self._worker is not None:
                    self._worker.prepare_denoiser()
                    if first is not None:  # drawn while Mitsuba starts (the path tracer's filter width, if JIT)
                        self._prefetch(first[0], first[1], 0, settings.filter_width)
            self.view = view or PathTraceView(scene, settings, variant=variant)
        except BaseException:
            self.close()
            raise
        if denoise and self._worker is None:  # raster: the labels' view, shared; guides filtered like the pixels
            self._guides = DenoiseGuides(scene, settings.guide_factor, raster=raster, filter_width=self.view.filter_width)

    @property
    def guides(self) -> DenoiseGuides | None:
        """The denoiser's guide renderer (on the worker thread: once it has drawn a keypoint), or None."""
        return self._worker.guides if self._worker is not None else self._guides

    def layouts(self) -> list[PassLayout]:
        intr = self.scene.camera.intrinsics
        return [layout(key, intr.width, intr.height)
                for key in color_keys(hdr=self.hdr, raw=self.keep_raw, sample_counts=self.sample_counts)]

    def attributes(self) -> dict[str, Any]:
        s, plan = self.settings, self.settings.plan()
        return {"mitsuba_variant": self.view.variant, "samples": plan.max_samples,
                "min_samples": plan.min_samples if plan.adaptive else plan.max_samples,
                "noise_threshold": plan.noise_threshold, "adaptive_sampling": plan.adaptive,
                "clamp_indirect": s.clamp_indirect if self.view.clamped else 0.0,
                "filter_glossy": s.filter_glossy if self.view.own_integrator else 0.0,
                **({"edge_min_samples": plan.edge_min_samples} if plan.edge_floor and self.denoise else {}),
                **({"edge_noise_scale": plan.edge_noise_scale}
                   if plan.edge_floor and self.denoise and plan.edge_noise_scale else {}),
                **({"edge_raw_weight": s.edge_raw_weight} if s.edge_raw_weight > 0 and self.denoise else {}),
                "pixel_filter": (f"Blackman-Harris, filter_width {self.view.filter_width} px" if self.view.filter_width
                                 else "box, 1 px"),
                "min_bounces": s.min_bounces, "max_bounces": s.max_bounces, "mitsuba_max_depth": s.max_bounces + 2,
                **{name: value for name, value in s.lobe_limits().items()},
                **({"caustics_refractive": False} if self.view.own_integrator and not s.caustics_refractive else {}),
                "color_encoding": "sRGB transfer of linear radiance clipped to [0, 1]", "denoised": self.denoise}

    def records(self) -> dict[str, np.ndarray]:
        return {}

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        return self.produce_later(index, cam2world, eye)()

    def produce_later(self, index: int, cam2world: np.ndarray, eye: int = 0) -> Callable[[], dict[str, Any]]:
        """Traces keypoint ``index`` now and returns the call that gives its values: with ``denoise`` the
        denoising and encoding run meanwhile on a thread of their own, so that the keypoint loop can trace the
        next keypoint while Open Image Denoise works on this one (:func:`hybridgen.render.keypoint_loop.run_keypoints`;
        the same values as in order)."""
        plan = self.settings.plan()
        guides: KeypointGuides | None = None
        if self._worker is not None:  # guides drawn on their own thread: since prefetch(), or from now
            key = _ahead_key(index, cam2world, eye, self.view.filter_width)
            guides = self._ahead.pop(key, None) or self._worker_guides(cam2world, self.view.filter_width)
            self._ahead = {k: v for k, v in self._ahead.items() if k[0] > index}  # a later keypoint's, if any
        elif self._guides is not None and plan.edge_floor:  # the shared raster: drawn here, filtered meanwhile
            fine = self._guides.draw(cam2world, self.view)
            guides = KeypointGuides(partial(self._guides.filtered, fine))
            self._filtering_thread().submit(guides.prepare)  # filtered, edges found while the first round samples
        edges = guides.edges if guides is not None and self.denoise and plan.edge_floor else None
        textured = guides.textured if guides is not None and self.denoise and plan.texture_floor else None
        pool = self._edge_pool() if edges is not None else None
        linear, counts = self.view.render_with_counts(cam2world, keypoint_seed(self.seed, index, eye), edges=edges,
                                                      pool=pool, textured=textured)
        pooled = pool.image() if pool is not None and pool.started else None
        values: dict[str, Any] = {}
        if self.keep_raw:
            values["colors_raw"] = self.encode(linear)
        if self.sample_counts:
            values["sample_counts"] = counts
        if guides is None and self._guides is not None:  # drawn here, on the GL context's thread, and filtered
            guides = KeypointGuides(partial(self._guides.filtered, self._guides.draw(cam2world, self.view)))
        finish = partial(self._finish, values, linear, guides, pooled)
        if not self.denoise:
            return finish
        if self._denoiser is None:
            self._denoiser = ThreadPoolExecutor(max_workers=1, thread_name_prefix="hybridgen-denoise")
        return self._denoiser.submit(finish).result

    def prefetch(self, index: int, cam2world: np.ndarray, eye: int = 0) -> None:
        """Starts drawing keypoint ``index``'s guides on the guide worker, ahead of :meth:`produce_later` (the
        keypoint loop calls it one keypoint ahead where the objects stay put:
        :func:`hybridgen.render.keypoint_loop.run_keypoints`), so that they are drawn while the keypoint before is
        traced instead of while this one's first round is; nothing without a worker (the shared raster view draws on
        the caller's thread)."""
        self._prefetch(index, cam2world, eye, self.view.filter_width)

    def _prefetch(self, index: int, cam2world: np.ndarray, eye: int, filter_width: float) -> None:
        key = _ahead_key(index, cam2world, eye, filter_width)
        if self._worker is not None and key not in self._ahead:
            self._ahead[key] = self._worker_guides(cam2world, filter_width)

    def _worker_guides(self, cam2world: np.ndarray, filter_width: float) -> KeypointGuides:
        """The worker's guides of ``cam2world`` for pixels of ``filter_width``, submitted now; their edges and
        textured pixels are found on the filtering thread as soon as they are drawn (not on the render loop's thread
        when the first round asks)."""
        assert self._worker is not None
        guides = KeypointGuides(partial(self._worker.result, self._worker.submit(cam2world, filter_width)))
        if self.denoise and self.settings.plan().edge_floor:
            self._filtering_thread().submit(guides.prepare)
        return guides

    def _filtering_thread(self) -> ThreadPoolExecutor:
        if self._filtering is None:
            self._filtering = ThreadPoolExecutor(max_workers=1, thread_name_prefix="hybridgen-guide-filter")
        return self._filtering

    def _edge_pool(self) -> PooledEdges | None:
        """The view's pool of edge pixels' samples when raw samples are mixed back on edges (made once per view)."""
        if self.settings.edge_raw_weight <= 0 or not self.denoise:
            return None
        if self._pool is None:
            self._pool = self.view.pooled_edges() or False
        return self._pool or None

    def _finish(self, values: dict[str, Any], linear: np.ndarray, guides: KeypointGuides | None,
                pooled: np.ndarray | None = None) -> dict[str, Any]:
        """``values`` completed with the keypoint's colors: ``linear`` denoised with the keypoint's ``guides`` when
        denoising (and the raw samples - ``pooled`` where given - mixed back on edges, :mod:`hybridgen.render.edge_blend`),
        then encoded."""
        if guides is not None:
            denoised = oidn_denoise(linear, *guides.get())
            linear = mix_raw_on_edges(denoised, linear, guides.strength(), self.settings.edge_raw_weight, pooled) \
                if self.settings.edge_raw_weight > 0 else denoised
        values["colors"] = self.encode(linear)
        if self.hdr:
            values["colors_hdr"] = linear.astype(np.float16)
        return values

    def view_changed(self) -> None:
        """The scene's objects moved or the intrinsics changed between keypoints: Mitsuba's scene is built anew
        (its meshes are stored in world coordinates, its sensor holds the intrinsics)."""
        self.view = PathTraceView(self.scene, self.settings, variant=self.view.variant)
        self._pool = None

    def close(self) -> None:
        """Release the denoising guides' GL resources and thread and the denoising thread (the Mitsuba scene goes
        with this producer)."""
        for pool in (self._denoiser, self._filtering):
            if pool is not None:  # what has not started (a prefetched keypoint's, after an error) is dropped
                pool.shutdown(wait=True, cancel_futures=True)
        self._denoiser = self._filtering = None
        if self._guides is not None:
            self._guides.release()
            self._guides = None
        if self._worker is not None:
            worker, self._worker = self._worker, None
            worker.release()


def _ahead_key(index: int, cam2world: np.ndarray, eye: int, filter_width: float) -> tuple[int, int, bytes, float]:
    """What identifies a keypoint's prefetched guides: the keypoint, the eye, the pose and the pixel filter."""
    return index, eye, np.asarray(cam2world).tobytes(), float(filter_width)


def render_color(scene: Scene, sinks: Iterable[FrameSink], settings: PathTraceSettings | None = None, *,
                 labels: LabelRequest | None = None, seed: int = 0, variant: str | None = None,
                 hdr: bool = False, denoise: bool = False, stereo_baseline: float | None = None,
                 default_category_id: int | None = None, progress: ProgressFactory | None = None,
                 indices: Sequence[int] | None = None, keep_raw: bool = False, sample_counts: bool = False,
                 encode: Callable[[np.ndarray], np.ndarray] | None = None) -> int:
    """Color (and ``labels`` if given) of every keypoint, as left/right pairs when ``stereo_baseline`` (m).
    ``keep_raw``, ``sample_counts`` and ``encode`` as in :class:`ColorProducer`. Stops with one line when a base-color texture a
    mesh names is missing (:func:`hybridgen.io.texture_needs.require_base_colors`; ``--lenient``: a notice)."""
    require_base_colors(scene.objects)
    sinks = list(sinks)
    producers: list[Producer] = []
    raster = None  # one raster view for labels and denoising guides (guides alone: ColorProducer's own thread)
    if labels is not None:
        raster = SceneRaster(scene, normals_space=labels.normals_space, depth_background=labels.depth_background)
    try:
        if labels is not None:
            producers.append(LabelProducer(scene, labels.with_sinks(sinks), default_category_id=default_category_id,
                                           raster=raster))
        start = indices[0] if indices is not None and len(indices) else 0  # the loop's first keypoint: its guides
        first = (start, scene.camera.keypoints[start]) if 0 <= start < len(scene.camera) and \
            stereo_baseline is None and not varies_per_keypoint(scene) else None  # are drawn while Mitsuba starts
        producers.insert(0, ColorProducer(scene, settings or PathTraceSettings(), seed=seed, variant=variant,
                                          hdr=hdr, denoise=denoise, keep_raw=keep_raw, sample_counts=sample_counts,
                                          raster=raster, first=first, encode=encode))
        if stereo_baseline is not None:
            producers = [StereoProducer(producers, stereo_baseline, scene)]
        return run_keypoints(scene, sinks, producers, progress=progress, what="color", indices=indices)
    finally:
        if raster is not None:
            raster.release()
