"""hybridgen's default color of a scene's keypoint 0 rendered in this process, step by step (adaptive sampling,
raster guides, OIDN), as tools/default_color_process.py renders it whole (seed 1): the frames and the CPU seconds
of sampling and of denoising."""
from __future__ import annotations

from typing import Any

from harness import cpu_seconds


def default_render(scene: Any, settings: Any) -> dict[str, Any]:
    """The default pipeline's raw and denoised sRGB frames (uint8), samples per pixel, sampling and denoising CPU
    seconds (``trace_cpu``, ``denoise_cpu``), and the path-trace view (for further tracing)."""
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.pathtrace.denoise import denoise
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.render_color import keypoint_seed
    from hybridgen.render.tonemap import to_srgb8

    view = PathTraceView(scene, settings)
    guides = DenoiseGuides(scene, filter_width=view.filter_width)
    pose = scene.camera.keypoints[0]
    try:
        start = cpu_seconds()
        linear, counts = view.render_with_counts(pose, keypoint_seed(1, 0))
        traced = cpu_seconds()
        denoised = denoise(linear, *guides.render(pose, view))
        done = cpu_seconds()
    finally:
        guides.release()
    return {"raw": to_srgb8(linear), "denoised": to_srgb8(denoised), "counts": counts, "view": view,
            "trace_cpu": traced - start, "denoise_cpu": done - traced}
