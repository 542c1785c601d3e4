"""``bproc.writer.write_bop``: BlenderProc 2.8's BOP dataset (https://github.com/thodan/bop_toolkit, the
``bop_datasets_format``) of the session's frames, from the colors and depth images ``render()`` returned.

What and where, as BlenderProc writes it (the files themselves are written by hybridgen's BOP writer,
:class:`hybridgen.io.bop_writer.BopWriter`)::

    <output_dir>/<dataset>/camera.json                 cx, cy, fx, fy (px), width, height, depth_scale
    <output_dir>/<dataset>/train_pbr/<chunk:06d>/rgb/<im:06d>.png|.jpg, depth/<im:06d>.png,
        mask/ and mask_visib/<im:06d>_<gt:06d>.png, scene_camera.json, scene_gt.json, scene_gt_info.json,
        scene_gt_coco.json                             (masks, info and COCO with ``calc_mask_info_coco``)

- Objects: ``target_objects``; else the visible mesh objects whose custom property ``bop_dataset_name`` is
  ``dataset`` (with a dataset), else every visible mesh object. ``obj_id`` is the custom property
  ``category_id`` (an integer >= 1 here).
- Poses of frame ``f`` (objects and camera as keyed there) in OpenCV camera axes (x right, y down, z forward):
  ``cam_R_m2c`` row-major 3x3 without the object's scale, ``cam_t_m2c`` in ``annotation_unit`` (mm by default;
  any ``m2mm`` given means mm, with BlenderProc's deprecation warning); objects more than ``ignore_dist_thres``
  metres from the camera are left out. ``scene_camera.json``: ``cam_K`` (px), ``depth_scale`` and, with
  ``save_world2cam``, ``cam_R_w2c``/``cam_t_w2c`` (same unit).
- Depth PNG: uint16 ``round(depth [m] * 1000 / depth_scale)``, so value * depth_scale = mm; farther pixels
  (Cycles' 1e10 background too) saturate at 65535 as in BlenderProc (hybridgen's own configs write 0 there).
- Appending (``append_to_existing_output``, default True; without it an existing dataset folder is an error):
  the last chunk's image ids continue, a new chunk every ``frames_per_chunk`` images - the render, write, reset
  loop of BlenderProc's BOP examples.

Differences: masks are exact (the instance map of a labels render of the session's visible mesh objects, and
each object's own silhouette), where BlenderProc estimates ``mask_visib`` from the depth PNG with tolerance
``delta`` and renders ``mask`` from the first object of each ``category_id``: ``delta`` and ``num_worker`` change
nothing. ``scene_gt_coco.json`` names each image with its real extension (BlenderProc always writes ``.jpg``)
and has no timestamps. A hidden object in ``target_objects`` is annotated only without masks.
"""
from __future__ import annotations

import os
import warnings
from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..logs import LOGGER
from .label_scene import label_scene, merged_mesh
from .session import SESSION
from .types import MeshObject
from .types.unsupported import fail

ANNOTATION_UNITS = ("m", "dm", "cm", "mm")
DEPTH_PNG_MAX = 65535
"""The largest value of a 16-bit depth PNG; farther depth saturates there (BlenderProc's writer)."""


def dataset_objects(target_objects: Sequence[MeshObject] | None, dataset: str) -> list[MeshObject]:
    """The objects to annotate, chosen as BlenderProc chooses them (see the module documentation)."""
    if target_objects is not None:
        objects = list(target_objects)
        for obj in objects:
            if obj.is_hidden():
                LOGGER.warning("The given object %s is hidden. However, the bop writer will still add annotations "
                               "for it.", obj.get_name())
    else:
        objects = [e for e in SESSION.entities if isinstance(e, MeshObject) and not e.is_hidden()
                   and (not dataset or (e.has_cp("bop_dataset_name") and e.get_cp("bop_dataset_name") == dataset))]
    if not objects:
        raise InputError(f"The scene does not contain any object from the specified dataset: {dataset}. Either remove "
                         "the dataset parameter or assign custom property 'bop_dataset_name' to selected objects")
    for obj in objects:
        if not obj.has_cp("category_id"):
            raise InputError(f"{obj.get_name()} object has no custom property 'category_id'")
        value = obj.get_cp("category_id")
        if isinstance(value, bool) or not float(value).is_integer() or int(value) < 1:
            raise InputError(f"object '{obj.get_name()}': its BOP obj_id is its category_id, which must be an integer "
                             f">= 1, got {value!r}")
    return objects


def frame_images(images: Sequence[Any] | None, what: str, count: int) -> list[np.ndarray]:
    """One image per rendered frame (``count``), or one line saying what is wrong."""
    if images is None:
        raise InputError(f"bproc.writer.write_bop needs {what}: a list with one image per frame "
                         f"(data['{what}'] of bproc.renderer.render())")
    if len(images) != count:
        raise InputError(f"The amount of images stored in the {what} ({len(images)}) does not correspond to the "
                         f"amount of images specified by frame_start to frame_end ({count}).")
    return [np.asarray(image) for image in images]


def write_bop(output_dir: str, target_objects: Sequence[MeshObject] | None = None,
              depths: Sequence[np.ndarray] | None = None, colors: Sequence[np.ndarray] | None = None,
              color_file_format: str = "PNG", dataset: str = "", append_to_existing_output: bool = True,
              depth_scale: float = 1.0, jpg_quality: int = 95, save_world2cam: bool = True,
              ignore_dist_thres: float = 100., m2mm: bool | None = None, annotation_unit: str = "mm",
              frames_per_chunk: int = 1000, calc_mask_info_coco: bool = True, delta: float = 0.015,
              num_worker: int | None = None) -> None:
    """Write the session's frames as a BOP dataset under ``<output_dir>/<dataset>`` (see the module
    documentation); ``depths`` in metres, ``colors`` uint8 RGB, one per frame."""
    import hybridgen as hg

    from ..config.options import checked_options
    from ..io.bop_writer import BopOptions, BopWriter
    from ..io.frame_sink import PassLayout

    frames = list(range(SESSION.frame_start, SESSION.frame_end))
    dataset_dir = os.path.join(output_dir, dataset)
    if os.path.exists(dataset_dir) and not append_to_existing_output:
        raise InputError(f"The output folder already exists: {dataset_dir}")
    objects = dataset_objects(target_objects, dataset)
    if annotation_unit not in ANNOTATION_UNITS:
        raise InputError(f"Invalid annotation unit: `{annotation_unit}`. Supported are 'm', 'dm', 'cm', 'mm'")
    if m2mm is not None:
        warnings.warn("bproc.writer.write_bop: m2mm is deprecated; annotation_unit='mm' is used", DeprecationWarning,
                      stacklevel=2)
        annotation_unit = "mm"
    color_images, depth_images = frame_images(colors, "colors", len(frames)), frame_images(depths, "depth", len(frames))
    hidden = [obj.get_name() for obj in objects if obj.is_hidden()]
    if calc_mask_info_coco and hidden:
        fail("bproc.writer.write_bop(calc_mask_info_coco=True) with hidden target_objects",
             f"{hidden[:3]} have no pixels in the labels render")
    visible = [e for e in SESSION.entities if isinstance(e, MeshObject) and not e.is_hidden()]
    scene, meshes = label_scene(frames, visible)
    annotated = [meshes[id(obj)] if id(obj) in meshes else merged_mesh(obj, frames[0]) for obj in objects]
    for obj, mesh in zip(objects, annotated):
        mesh.category_id = int(obj.get_cp("category_id"))
    options = checked_options(BopOptions, dataset=dataset, append=True, depth_scale=float(depth_scale),
                              color_file_format=color_file_format, jpg_quality=int(jpg_quality),
                              frames_per_chunk=int(frames_per_chunk), annotation_unit=annotation_unit,
                              save_world2cam=bool(save_world2cam), calc_mask_info_coco=bool(calc_mask_info_coco),
                              ignore_dist_thres=float(ignore_dist_thres))
    writer = BopWriter(output_dir, scene, lambda: annotated, options, log=LOGGER.info)
    height, width = color_images[0].shape[:2]
    records = {"cam_K": np.stack([scene.camera.intrinsics.K] * len(frames)),
               "cam2world": np.stack(scene.camera.keypoints)}
    layouts = [PassLayout("colors", "uint8", (height, width, 3), units="sRGB"),
               PassLayout("depth", "float32", (height, width), units="m")]
    farthest = DEPTH_PNG_MAX * float(depth_scale) / 1000.0  # m
    try:
        writer.begin(len(frames), layouts, records, {})
        for index, frame in enumerate(frames):
            for obj, mesh in zip(objects, annotated):
                mesh.local2world = obj.world_matrix(frame)
            writer.write(index, {"colors": color_images[index],
                                 "depth": np.minimum(depth_images[index].astype(np.float64), farthest)})
        if calc_mask_info_coco:
            hg.render_labels(scene, [writer], hg.LabelRequest(depth=False, normals=False, map_by=["instance"]))
        writer.end()
        writer.finalize()
    except BaseException:
        writer.abort()
        raise
