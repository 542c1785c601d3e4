"""The BOP dataset layout (https://github.com/thodan/bop_toolkit/blob/master/docs/bop_datasets_format.md), as
BlenderProc's ``BopWriter`` writes it::

    <output_dir>/<dataset>/camera.json                       cx, cy, fx, fy [px], width, height, depth_scale
    <output_dir>/<dataset>/train_pbr/<chunk, 6 digits>/
        rgb/<im_id>.png|.jpg                                 colors (sRGB)
        depth/<im_id>.png                                    uint16; depth [mm] = value * depth_scale, 0 = none
        mask/<im_id>_<gt_id>.png, mask_visib/<im_id>_<gt_id>.png   255 inside the full / the visible silhouette
        scene_camera.json   per image: cam_K, depth_scale, cam_R_w2c, cam_t_w2c
        scene_gt.json       per image: [{cam_R_m2c, cam_t_m2c, obj_id}, ...] in gt_id order
        scene_gt_info.json  per image and gt: bbox_obj, bbox_visib, px_count_all, px_count_valid,
                            px_count_visib, visib_fract
        scene_gt_coco.json  COCO annotations of the visible masks (uncompressed RLE, amodal boxes)

Frames and units: camera poses and object poses are in OpenCV camera axes (x right, y down, z forward);
translations in the annotation unit (mm by default), rotations row-major 3x3. ``cam_R_m2c`` is the
rotation of the object's local frame: an object scale (``local2world`` with scale) is not part of it, so
BOP models of scaled objects must be the scaled mesh (in mm). Every object gets ``obj_id`` = its
``category_id`` (objects of one ``obj_id`` must share one model).

Masks are exact, not estimated from depth with a tolerance as the BOP toolkit does for real data:
``mask_visib`` is the object's pixels in our instance map; ``mask`` (full, amodal), ``px_count_all`` (the
full silhouette also outside the image, as the BOP toolkit counts it), ``visib_fract`` and the toolkit boxes
``bbox_obj``/``bbox_visib`` (``[x, y, x_max - x, y_max - y]`` of the full / visible pixels, [-1, -1, -1, -1]
when nothing is visible; ``bbox_obj`` may extend past the image) are the render-side passes
``amodal_masks``, ``visible_fractions`` and ``object_boxes`` (:mod:`hybridgen.render.raster.object_passes`), which
this writer asks for (``wanted_passes``); ``px_count_valid`` counts full-mask pixels with a depth value in
the PNG. Poses: :mod:`hybridgen.scene.rigid_pose`; chunks and their JSON: :mod:`hybridgen.io.bop_chunks`.

Appending continues the last chunk's image ids (a new chunk every ``frames_per_chunk`` images). Files are
staged under temporary names and renamed, the JSON files last, only when the run commits.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from ..render.passes import hint
from ..scene.mesh_object import MeshObject
from ..scene.rigid_pose import model_to_camera
from ..scene.scene import Scene
from .atomic import confined_path, prepare_output_dir
from .bop_chunks import Chunks
from .bop_options import ANNOTATION_UNITS, BopOptions
from .bop_json import camera_json_text
from .coco_content import annotation
from .depth_png import depth_png_values
from .frame_sink import PassLayout
from .image_files import StagedFiles, jpeg_bytes, png_bytes, write_file
from .mask_encoding import bbox_of, rle_uncompressed
from .output_lock import hold_output_lock

NEEDED_KEYS = {key: hint(key) for key in ("colors", "depth", "instance_segmaps")}
OBJECT_PASSES = ("amodal_masks", "visible_fractions", "object_boxes")
"""The render-side passes this writer asks for when it writes masks (they come with ``instance_segmaps``)."""
NO_BOX = [-1, -1, -1, -1]
__all__ = ["ANNOTATION_UNITS", "BopOptions", "BopWriter", "needed_keys"]


def needed_keys(with_masks: bool) -> dict[str, str]:
    """The keys a BOP dataset needs, with how to make them (instance maps only ``with_masks``)."""
    return {key: how for key, how in NEEDED_KEYS.items() if key != "instance_segmaps" or with_masks}


@dataclass
class _Frame:
    """What one keypoint has received so far (its inputs may come from several renderers)."""

    objects: list[tuple[int, MeshObject]] = field(default_factory=list)  # (gt_id, object) annotated in scene_gt
    colors: bool = False
    depth: bool = False
    masks_done: bool = False
    valid: np.ndarray | None = None  # pixels with a depth value, until px_count_valid is known
    full_masks: list[np.ndarray] | None = None
    info: list[dict[str, Any]] = field(default_factory=list)


class BopWriter:
    """Frame sink writing a BOP dataset (see the module documentation) with ``options`` (validated where
    they were made; the defaults without). ``select()`` gives the objects to annotate, called once at the
    first renderer."""

    def __init__(self, output_dir: str | Path, scene: Scene, select: Callable[[], list[MeshObject]] | None = None,
                 options: BopOptions | None = None, *, log: Callable[[str], None] | None = None) -> None:
        opts = options if options is not None else BopOptions()
        self.scene, self.select = scene, select
        self.output_dir = prepare_output_dir(Path(output_dir))
        self.dataset_dir = (confined_path(self.output_dir, opts.dataset, "dataset") if opts.dataset
                            else self.output_dir)
        self.dataset_name = opts.dataset or self.output_dir.resolve().name
        chunks_dir = self.dataset_dir / "train_pbr"
        for folder in (self.dataset_dir, chunks_dir):
            if folder.exists() and not folder.is_dir():
                raise InputError(f"'{folder}' exists and is not a directory")
        self.depth_scale, self.unit = float(opts.depth_scale), ANNOTATION_UNITS[opts.annotation_unit]
        self.extension = ".png" if opts.color_file_format == "PNG" else ".jpg"
        self.jpg_quality, self.save_world2cam = int(opts.jpg_quality), opts.save_world2cam
        self.calc_mask_info_coco, self.ignore_dist_thres = opts.calc_mask_info_coco, float(opts.ignore_dist_thres)
        self.log = log or (lambda message: None)
        self._unlock = hold_output_lock(self.output_dir)  # ids and chunks stay ours until finalize/abort
        try:
            self.chunks = Chunks(chunks_dir, opts.frames_per_chunk, append=opts.append,
                                 with_info=opts.calc_mask_info_coco)
        except BaseException:
            self._unlock()
            raise
        self.count = 0
        self.camera: dict[str, np.ndarray] = {}
        self.depth_background = float("inf")
        self.objects: list[MeshObject] | None = None
        self.image_size: tuple[int, int] | None = None
        self.frames: dict[int, _Frame] = {}
        self.too_far = 0
        self._staged = StagedFiles()

    # ------------------------------------------------------------------ FrameSink
    def wanted_passes(self) -> tuple[str, ...]:
        """The render-side per-object passes this writer needs (none without masks)."""
        return OBJECT_PASSES if self.calc_mask_info_coco else ()

    def wanted_objects(self) -> list[int] | None:
        """The annotated objects, whose per-object passes alone are made (known once ``begin`` chose them)."""
        return None if self.objects is None else [obj.instance_id for obj in self.objects]

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        """Check the renderer's output and pick the annotated objects (once)."""
        if any(layout.stereo for layout in layouts):
            raise InputError("writer.BopWriter does not support stereo renders; render the eyes as keypoints")
        if self.count and n_keypoints != self.count:
            raise InputError(f"renderers disagree on the keypoint count ({self.count} vs {n_keypoints})")
        self.count = n_keypoints
        for key in ("cam_K", "cam2world"):
            if key in camera_records:
                self.camera[key] = np.asarray(camera_records[key], dtype=np.float64)
        for layout in layouts:
            if layout.key == "depth" and layout.background is not None:
                self.depth_background = layout.background
            if self.image_size is None and layout.image_size is not None:
                self.image_size = layout.image_size
        if self.objects is None:
            objects = self.select() if self.select is not None else list(self.scene.objects)
            bad = [o.name for o in objects if not isinstance(o.category_id, (int, np.integer)) or o.category_id < 1]
            if bad:
                raise InputError(f"writer.BopWriter: the BOP obj_id is the category_id, an integer >= 1; object(s) "
                                 f"{bad[:10]} have none (set category_id, or leave them out with 'selector')")
            self.objects = objects

    def write(self, index: int, values: dict[str, Any]) -> None:
        """Stage the files of keypoint ``index`` and compute its annotations as their inputs arrive."""
        frame = self.frames.get(index)
        if frame is None:
            frame = self.frames[index] = self._pose_records(index)
        _, im_id = self.chunks.position(index)
        if "colors" in values:
            rgb = np.asarray(values["colors"])
            data = png_bytes(rgb) if self.extension == ".png" else jpeg_bytes(rgb, self.jpg_quality)
            self._staged.add(self._path(index, "rgb", f"{im_id:06d}{self.extension}"), data)
            frame.colors = True
        if "depth" in values:
            units, too_far = depth_png_values(values["depth"], self.depth_scale, self.depth_background)
            self.too_far += too_far
            self._staged.add(self._path(index, "depth", f"{im_id:06d}.png"), png_bytes(units))
            frame.depth, frame.valid = True, units > 0
        if "instance_segmaps" in values and self.calc_mask_info_coco:
            missing = [key for key in OBJECT_PASSES if key not in values]
            if missing:
                raise InputError(f"writer.BopWriter: the renderer did not deliver {missing} with instance_segmaps")
            self._masks(index, np.asarray(values["instance_segmaps"]), values, frame)
        if frame.valid is not None and frame.full_masks is not None:
            for record, mask in zip(frame.info, frame.full_masks, strict=True):
                record["px_count_valid"] = int(np.count_nonzero(frame.valid & mask))
            frame.valid = frame.full_masks = None

    def end(self) -> None:
        """Nothing to flush: files are staged as keypoints arrive."""

    # ------------------------------------------------------------------ per keypoint
    def _path(self, index: int, folder: str, name: str) -> Path:
        directory = self.chunks.folder(self.chunks.position(index)[0]) / folder
        self._staged.make_dir(directory)
        return directory / name

    def _pose_records(self, index: int) -> _Frame:
        """scene_camera and scene_gt entries of keypoint ``index`` (poses only: no image needed)."""
        assert self.objects is not None
        chunk, im_id = self.chunks.of(index)
        world2cam = np.linalg.inv(self.camera["cam2world"][index])
        entry: dict[str, Any] = {"cam_K": self.camera["cam_K"][index].ravel().tolist(), "depth_scale": self.depth_scale}
        if self.save_world2cam:
            entry["cam_R_w2c"] = world2cam[:3, :3].ravel().tolist()
            entry["cam_t_w2c"] = (world2cam[:3, 3] * self.unit).tolist()
        chunk.camera[im_id] = entry
        frame, gts = _Frame(), []
        for obj in self.objects:
            if np.linalg.norm((world2cam @ obj.local2world)[:3, 3]) > self.ignore_dist_thres:
                self.log(f"BOP: object '{obj.name}' is more than {self.ignore_dist_thres} m from the camera at "
                         f"keypoint {index}; left out of scene_gt")
                continue
            rotation, translation = model_to_camera(world2cam, obj.local2world, obj.name)
            frame.objects.append((len(gts), obj))
            gts.append({"cam_R_m2c": rotation.ravel().tolist(), "cam_t_m2c": (translation * self.unit).tolist(),
                        "obj_id": int(obj.category_id)})
        chunk.gt[im_id] = gts
        return frame

    def _masks(self, index: int, instance: np.ndarray, values: dict[str, Any], frame: _Frame) -> None:
        """Full and visible masks, scene_gt_info and COCO entries of keypoint ``index`` from the instance map
        and the per-object passes."""
        chunk, im_id = self.chunks.of(index)
        height, width = instance.shape
        amodal, fractions, boxes = (values[key] for key in OBJECT_PASSES)
        masks = []
        for gt_id, obj in frame.objects:
            idx = obj.instance_id
            full = np.asarray(amodal[idx], dtype=bool)
            visible = instance == idx
            counts, box = fractions[idx], boxes[idx]
            count_visib = int(counts["px_count_visib"])
            info = {"bbox_obj": list(box["bbox_obj"]) if count_visib else list(NO_BOX),
                    "bbox_visib": list(box["bbox_visib"]) if count_visib else list(NO_BOX),
                    "px_count_all": int(counts["px_count_all"]), "px_count_valid": 0, "px_count_visib": count_visib,
                    "visib_fract": counts["visib_fract"]}
            frame.info.append(info)
            masks.append(full)
            name = f"{im_id:06d}_{gt_id:06d}.png"
            self._staged.add(self._path(index, "mask", name), png_bytes(full.astype(np.uint8) * 255))
            self._staged.add(self._path(index, "mask_visib", name), png_bytes(visible.astype(np.uint8) * 255))
            if count_visib and full.any():
                chunk.coco_annotations.append(annotation(
                    im_id, int(obj.category_id), count_visib, bbox_of(full), rle_uncompressed(visible),
                    width=width, height=height, ignore=bool(info["visib_fract"] < 0.1)))
        chunk.info[im_id] = frame.info
        chunk.coco_images.append({"id": im_id, "file_name": f"rgb/{im_id:06d}{self.extension}",
                                  "width": width, "height": height})
        frame.full_masks, frame.masks_done = masks, True

    # ------------------------------------------------------------------ commit
    def missing_keys(self) -> list[str]:
        """Needed keys some keypoint never received."""
        frames = [self.frames.get(i, _Frame()) for i in range(self.count)]
        received = {"colors": all(f.colors for f in frames), "depth": all(f.depth for f in frames),
                    "instance_segmaps": all(f.masks_done for f in frames)}
        return [key for key in needed_keys(self.calc_mask_info_coco) if not received[key]]

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        """Rename every staged file and write the JSON files; returns ``[the dataset folder]``. Scene
        ``records`` and run ``attributes`` are not part of BOP."""
        if self.count == 0:
            raise InputError("no keypoint was rendered before the BOP writer")
        missing = self.missing_keys()
        if missing:
            raise InputError(f"a BOP dataset needs {missing} for every keypoint: "
                             + "; ".join(NEEDED_KEYS[k] for k in missing))
        if self.too_far:
            self.log(f"BOP: {self.too_far} depth pixel(s) beyond {65535 * self.depth_scale:.0f} mm were written as 0 "
                     "(no depth); raise depth_scale to keep them")
        texts = self._json_texts()
        self._staged.commit()
        for path, text in texts.items():
            write_file(path, text.encode("utf-8"), durable=True)
        self._unlock()
        return [self.dataset_dir]

    def abort(self) -> None:
        """Delete everything staged (and the folders made for it); existing chunks stay as they were."""
        self._staged.discard()
        self._unlock()

    def _json_texts(self) -> dict[Path, str]:
        assert self.image_size is not None
        texts = {self.dataset_dir / "camera.json": camera_json_text(self.camera["cam_K"][0], self.depth_scale,
                                                                    *self.image_size)}
        for chunk_id in sorted(self.chunks.chunks):
            self._staged.make_dir(self.chunks.folder(chunk_id))
        categories = sorted({int(o.category_id) for o in self.objects or []})
        return texts | self.chunks.json_texts(self.dataset_name, categories)
