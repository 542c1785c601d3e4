"""Python API: the label passes of every keypoint, from the raster view, into frame sinks."""
from __future__ import annotations

from typing import Any, Iterable, Sequence

from ...io.frame_sink import FrameSink
from ...io.texture_needs import require_base_colors
from ...scene.scene import Scene
from ..keypoint_loop import ProgressFactory, StereoProducer, run_keypoints
from .label_producer import LabelProducer
from .label_request import LabelRequest
from .raster_view import RasterView

__all__ = ["LabelProducer", "render_labels"]  # LabelProducer lives in label_producer; kept importable here


def render_labels(scene: Scene, sinks: Iterable[FrameSink], request: LabelRequest | None = None, *,
                  default_category_id: int | None = None, view: RasterView | None = None,
                  progress: ProgressFactory | None = None, indices: Sequence[int] | None = None,
                  render_threads: int = 1, stereo_baseline: float | None = None) -> int:
    """Render the label passes of the keypoints ``indices`` (default: all) of ``scene.camera`` into ``sinks``
    (plus the on-request passes they ask for); returns how many. ``render_threads`` > 1: that many raster
    threads, each with its own GL context (render/raster/threaded_labels.py; same values, same order; ``view``
    then unused). ``stereo_baseline`` (m): left/right pairs as :func:`hybridgen.render_color` makes them
    (:class:`~hybridgen.render.keypoint_loop.StereoProducer`)."""
    sinks = list(sinks)
    request = (request or LabelRequest()).with_sinks(sinks)
    if request.albedo or "diffuse_color" in request.keys():  # they show base colors: their textures must exist
        # (io/texture_needs.py)
        require_base_colors(scene.objects)
    producer: Any
    if render_threads > 1:
        from .threaded_labels import ThreadedLabelProducer

        producer = ThreadedLabelProducer(scene, request, render_threads, producer_class=LabelProducer,
                                         default_category_id=default_category_id)
    else:
        producer = LabelProducer(scene, request, default_category_id=default_category_id, view=view)
    if stereo_baseline is not None:
        producer = StereoProducer([producer], stereo_baseline, scene)
    return run_keypoints(scene, sinks, [producer], progress=progress, what="labels", indices=indices)
