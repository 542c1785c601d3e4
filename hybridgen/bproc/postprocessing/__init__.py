"""``bproc.postprocessing`` of BlenderProc 2.8: conversions, filters and sensor noise on rendered images.

Images are NumPy arrays with rows x columns (x channels) axes, pixel (u, v) at column u, row v; depth and
distance in metres. Each function takes one image or a list of per-frame images (as ``bproc.renderer.render()``
returns them) and answers in kind, as BlenderProc's do. Functions that need the camera (intrinsics, stereo
baseline, the distance pass's range) read the current scene's, as BlenderProc does, and take hybridgen's
keyword-only ``K=`` / ``baseline=`` instead. OpenCV is needed only by ``stereo_global_matching`` and by
``oil_paint_filter``'s edge detection, and is imported when they are called.
"""
from __future__ import annotations

from .depth import depth2dist, dist2depth, trim_redundant_channels
from .lens import apply_lens_distortion
from .oil_paint import oil_paint_filter
from .segmap import remove_segmap_noise
from .sensor_noise import add_gaussian_shifts, add_kinect_azure_noise
from .stereo import stereo_global_matching

__all__ = ["add_gaussian_shifts", "add_kinect_azure_noise", "apply_lens_distortion", "depth2dist", "dist2depth",
           "oil_paint_filter", "remove_segmap_noise", "stereo_global_matching", "trim_redundant_channels"]
