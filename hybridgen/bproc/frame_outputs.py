"""One rendered frame's hybridgen values -> BlenderProc's data-dict values (keys by output kind), for
:mod:`hybridgen.bproc.render_frames`.

Per output kind (``SESSION.renderer.outputs``) and the color key:

- ``depth`` / ``distance``: float32 (H, W) m - antialiased depth float64, as BlenderProc's dist2depth makes it;
  background 1e10 (Cycles' Z pass) or, with antialiasing, the mist range (10000 m) - as distance, or as depth
  along each pixel's ray.
- ``normals``: float32 (H, W, 3), Blender camera axes (x right, y up, z backwards), ``0.5 n + 0.5``; 0.5 on the
  background.
- ``diffuse``: uint8 (H, W, 3) of Cycles' Diffuse Color pass (hybridgen's ``diffuse_color`` pass at pixel
  centres; Cycles averages a pixel's samples) through the colors' view transform, as Blender writes it (measured:
  Filmic changes BlenderProc's diffuse PNG as it changes the colors); 0 on the background, as in Cycles.
- ``segmentation``: :func:`hybridgen.bproc.segmentation.map_frame`'s keys.
- colors: uint8 (H, W, 3) through the view transform (:mod:`hybridgen.render.view_transform`: Filmic, BlenderProc's
  default, from Blender's tables where installed, else Standard sRGB); ``color_depth`` 16: uint16 of the linear
  float16 render through the same view; file
  format JPEG: the 8-bit image after a JPEG round trip at ``jpg_quality`` (what BlenderProc loads back from its
  ``.jpg``; Blender and hybridgen both keep full chroma above quality 90). With ``alpha`` (Cycles' transparent
  film) a fourth channel: full where a surface covers the pixel centre, 0 where the camera ray meets only the
  world, and there RGB 0 too (a straight-alpha PNG of Cycles' premultiplied film). Cycles' alpha is the pixel's
  coverage; hybridgen's is the pixel centre's, so an edge pixel is opaque with the world's light blended in.

Stereo frames (values with a leading axis of 2: left, right) give every image a leading axis of 2 as BlenderProc's
data dict holds them; ``instance_attribute_maps`` of a stereo frame is one list over both eyes.
"""
from __future__ import annotations

import io
from typing import Any, Sequence

import numpy as np

from ..scene.frames import blender_to_opencv
from .segmentation import map_frame
from .session import SESSION
from ..render.view_transform import STANDARD, ColorEncoding

BACKGROUND_DEPTH = 1e10
"""Cycles' Z pass where a pixel sees no surface (m)."""


def _with_alpha(colors: np.ndarray, background: np.ndarray) -> np.ndarray:
    """RGBA of RGB ``colors``: alpha the dtype's maximum, 0 with RGB 0 where ``background`` (H, W) is True."""
    full = np.iinfo(colors.dtype).max
    rgba = np.concatenate([colors, np.full(colors.shape[:2] + (1,), full, dtype=colors.dtype)], axis=2)
    rgba[background] = 0
    return rgba


def _colors(values: dict[str, Any], encoding: ColorEncoding) -> np.ndarray:
    settings = SESSION.renderer
    if settings.color_depth == 16 and "colors_hdr" in values:
        return encoding.to_uint16(np.asarray(values["colors_hdr"], dtype=np.float32)[..., :3])
    colors = np.asarray(values["colors"], dtype=np.uint8)[..., :3]
    if settings.file_format == "JPEG":
        from PIL import Image

        from ..io.image_files import jpeg_bytes

        colors = np.asarray(Image.open(io.BytesIO(jpeg_bytes(colors, settings.jpg_quality))).convert("RGB"))
    return colors


def _convert_eye(values: dict[str, Any], table: np.ndarray, cam2world: np.ndarray, meshes: Sequence[Any],
                 ray_lengths: np.ndarray, alpha: bool, encoding: ColorEncoding) -> dict[str, Any]:
    """One eye's values -> BlenderProc's values by output kind (``colors``: the color image)."""
    from ..io.hdf5_blenderproc import encode_normals

    outputs = SESSION.renderer.outputs
    converted: dict[str, Any] = {}
    instances = table[np.asarray(values["instance_segmaps"])] if "instance_segmaps" in values else None
    background = instances == 0 if instances is not None else None
    for kind, options in outputs.items():
        if kind in ("depth", "distance"):
            image = np.array(values[kind], dtype=np.float32)
            far = options["distance_max"] if options["antialiasing"] else BACKGROUND_DEPTH
            far_depth = far / ray_lengths if options["antialiasing"] else np.full_like(ray_lengths, far)
            image[background] = (far_depth if kind == "depth" else far_depth * ray_lengths)[background]
            # BlenderProc makes antialiased depth with dist2depth: float32 distances x float64 factors -> float64
            converted[kind] = image.astype(np.float64) if kind == "depth" and options["antialiasing"] else image
        elif kind == "normals":
            normals = encode_normals(values["normals"], blender_to_opencv(cam2world), "camera")
            normals[background] = 0.5
            converted[kind] = normals
        elif kind == "diffuse":
            converted[kind] = encoding.to_uint8(np.asarray(values["diffuse_color"])[..., :3])  # as the colors
        elif kind == "segmentation":
            converted[kind] = map_frame(instances, options["map_by"], options["default_values"], meshes)
    if "colors" in values:
        converted["colors"] = _colors(values, encoding)
        if alpha:
            converted["colors"] = _with_alpha(converted["colors"], background)
    return converted


def _merge_eyes(left: dict[str, Any], right: dict[str, Any]) -> dict[str, Any]:
    """Two eyes' converted values -> one stereo frame (images stacked on a leading axis of 2)."""
    merged: dict[str, Any] = {}
    for kind, value in left.items():
        if kind != "segmentation":
            merged[kind] = np.stack([value, right[kind]])
            continue
        segmentation: dict[str, Any] = {}
        for key, image in value.items():
            if key != "instance_attribute_maps":
                segmentation[key] = np.stack([image, right[kind][key]])
        records: dict[int, dict[str, Any]] = {}
        for record in value["instance_attribute_maps"] + right[kind]["instance_attribute_maps"]:
            records.setdefault(record["idx"], {}).update(record)
        segmentation["instance_attribute_maps"] = list(records.values())
        merged[kind] = segmentation
    return merged


def convert_frame(values: dict[str, Any], table: np.ndarray, cam2world: np.ndarray, meshes: Sequence[Any],
                  ray_lengths: np.ndarray, stereo: bool, alpha: bool = False,
                  encoding: ColorEncoding = STANDARD) -> dict[str, Any]:
    """One frame's values (stereo: each with a leading axis of 2) -> BlenderProc's values by output kind;
    ``alpha``: RGBA colors (transparent film); ``encoding``: the view transform of 16-bit colors (8-bit colors come
    encoded by the color producer)."""
    if not stereo:
        return _convert_eye(values, table, cam2world, meshes, ray_lengths, alpha, encoding)
    eyes = [{key: value[eye] for key, value in values.items()} for eye in (0, 1)]
    return _merge_eyes(*(_convert_eye(eye, table, cam2world, meshes, ray_lengths, alpha, encoding) for eye in eyes))
