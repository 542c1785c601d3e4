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
``mask_visib`` is the object's pixels in our instance map; ``mask`` (full, amodal) is the object rendered
alone in the raster pass. ``px_count_all`` counts the full silhouette also outside the image, as the BOP
toolkit does, on a canvas three times the image size (the image in its centre); ``px_count_valid`` counts
full-mask pixels with a depth value in the PNG; boxes follow the toolkit: ``bbox_obj``/``bbox_visib`` are
``[x, y, x_max - x, y_max - y]`` of the full / visible pixels, [-1, -1, -1, -1] when nothing is visible;
``bbox_obj`` may extend past the image.

Appending continues the last chunk's image ids (a new chunk every ``frames_per_chunk`` images). Files are
staged under temporary names and renamed, the JSON files last, only when the run commits.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from itertools import product
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..errors import InputError
from ..scene.camera import Intrinsics
from ..scene.mesh_object import MeshObject
from ..scene.scene import Scene
from .atomic import confined_path, prepare_output_dir
from .output_lock import hold_output_lock
from .frame_sink import PassLayout
from .image_files import StagedFiles, jpeg_bytes, png_bytes, write_file
from .mask_encoding import bbox_of, rle_uncompressed

ANNOTATION_UNITS = {"m": 1.0, "dm": 10.0, "cm": 100.0, "mm": 1000.0}
COLOR_FORMATS = ("PNG", "JPEG")
NEEDED_KEYS = {
    "colors": "render color with renderer.RgbRenderer before this writer",
    "depth": "set render_depth: true on the renderer",
    "instance_segmaps": "add 'instance' to map_by of the renderer",
}
MAX_CANVAS = 16384  # px per side the raster view accepts
NO_BOX = [-1, -1, -1, -1]


# ------------------------------------------------------------------------------------------------ helpers
def bop_json_text(content: dict[int, Any]) -> str:
    """BOP toolkit style: one line per image id, ids in numeric order, values with sorted keys."""
    lines = [f'  "{key}": {json.dumps(content[key], sort_keys=True)}' for key in sorted(content)]
    return "{\n" + ",\n".join(lines) + ("\n" if lines else "") + "}"


def _read_for_append(path: Path) -> Any:
    """The parsed JSON of a file a chunk is appended to; InputError when it is missing or unreadable."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"cannot append: '{path}' is missing (an incomplete BOP chunk?)") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"cannot append to '{path}': {exc}") from None


def load_bop_json(path: Path) -> dict[int, Any]:
    """A per-image BOP JSON file (``{"<im_id>": ...}``) with integer keys; InputError if it is not one."""
    content = _read_for_append(path)
    if not isinstance(content, dict) or not all(str(k).isdigit() for k in content):
        raise InputError(f"cannot append to '{path}': not a BOP per-image JSON object")
    return {int(k): v for k, v in content.items()}


def load_coco_json(path: Path) -> dict[str, Any]:
    """An existing ``scene_gt_coco.json`` to extend."""
    content = _read_for_append(path)
    if not isinstance(content, dict) or not all(isinstance(content.get(k), list)
                                                for k in ("images", "annotations", "categories")):
        raise InputError(f"cannot append to '{path}': not a COCO annotations file")
    return content


def rigid_rotation(linear: np.ndarray, name: str) -> np.ndarray:
    """The rotation of a 3x3 rotation-times-scale matrix (polar decomposition); mirrors are errors."""
    u, s, vt = np.linalg.svd(linear)
    if s.min() <= 0 or np.linalg.det(u @ vt) < 0:
        raise InputError(f"object '{name}' has a mirrored or degenerate pose: BOP poses are rotations")
    return u @ vt


def toolkit_box(xs: np.ndarray, ys: np.ndarray) -> list[int]:
    """The BOP toolkit's ``calc_2d_bbox``: ``[x_min, y_min, x_max - x_min, y_max - y_min]``."""
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min()), int(ys.max() - ys.min())]


def depth_png_values(depth: np.ndarray, depth_scale: float, background: float) -> tuple[np.ndarray, int]:
    """uint16 depth image (value * depth_scale = mm) of ``depth`` in metres, and how many valid pixels were
    too far for 16 bits (written as 0, "no depth", like background)."""
    depth = np.asarray(depth, dtype=np.float64)
    valid = np.isfinite(depth) & (depth > 0)
    if np.isfinite(background):
        valid &= depth != background
    units = np.rint(np.where(valid, depth, 0.0) * (1000.0 / depth_scale))
    too_far = valid & (units > 65535)
    units[too_far] = 0
    return units.astype(np.uint16), int(too_far.sum())


# ------------------------------------------------------------------------------------------ amodal masks
class AmodalMasks:
    """Full silhouettes of single objects, each drawn alone in the raster pass (exact at pixel centres).

    An object whose bounding box projects inside the image is drawn at image size; otherwise on a canvas
    of three times the image size with the image in its centre (same pixel centres), so that the pixels
    outside the image count too.
    """

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self._view: Any = None
        self._wide: Any = None

    def _render(self, wide: bool, cam2world: np.ndarray, intr: Intrinsics, obj: MeshObject) -> np.ndarray:
        from ..render.raster import RasterView  # GL only when a BOP dataset is written

        if wide and self._wide is None:
            self._wide = RasterView(self.scene)
        if not wide and self._view is None:
            self._view = RasterView(self.scene)
        view = self._wide if wide else self._view
        hidden = frozenset(o.instance_id for o in self.scene.objects if o is not obj)
        return view.render_raw(cam2world, intr, hidden=hidden).instance == obj.instance_id

    def silhouette(self, obj: MeshObject, cam2world: np.ndarray, intr: Intrinsics) -> tuple[np.ndarray, int, list[int]]:
        """``(mask inside the image, pixel count including outside, toolkit box in image pixels)``."""
        width, height = intr.width, intr.height
        world2cam = np.linalg.inv(cam2world)
        bounds = obj.bounds_local
        corners = np.array([[bounds[i, 0], bounds[j, 1], bounds[k, 2]] for i, j, k in product((0, 1), repeat=3)])
        obj2cam = world2cam @ obj.local2world
        cam = corners @ obj2cam[:3, :3].T + obj2cam[:3, 3]
        z = cam[:, 2]
        empty = np.zeros((height, width), dtype=bool)
        if (z <= intr.clip_start).all() or (z >= intr.clip_end).all():
            return empty, 0, list(NO_BOX)
        inside = False
        if (z > intr.clip_start).all():
            u = intr.K[0, 0] * cam[:, 0] / z + intr.K[0, 2]
            v = intr.K[1, 1] * cam[:, 1] / z + intr.K[1, 2]
            inside = u.min() >= -0.5 and v.min() >= -0.5 and u.max() <= width - 0.5 and v.max() <= height - 0.5
        if inside or 3 * max(width, height) > MAX_CANVAS:
            mask = self._render(False, cam2world, intr, obj)
            full, dx, dy = mask, 0, 0
        else:
            K = intr.K.copy()
            K[0, 2] += width
            K[1, 2] += height
            wide = Intrinsics(K, 3 * width, 3 * height, intr.clip_start, intr.clip_end)
            full = self._render(True, cam2world, wide, obj)
            mask, dx, dy = full[height:2 * height, width:2 * width], width, height
        ys, xs = np.nonzero(full)
        box = toolkit_box(xs - dx, ys - dy) if xs.size else list(NO_BOX)
        return np.ascontiguousarray(mask), int(xs.size), box

    def release(self) -> None:
        for view in (self._view, self._wide):
            if view is not None:
                view.release()
        self._view = self._wide = None


# -------------------------------------------------------------------------------------------- the writer
@dataclass
class _Chunk:
    """The per-image records of one chunk (existing ones first when appending to it)."""

    camera: dict[int, Any] = field(default_factory=dict)
    gt: dict[int, Any] = field(default_factory=dict)
    info: dict[int, Any] = field(default_factory=dict)
    coco: dict[str, Any] | None = None  # an existing scene_gt_coco.json
    coco_images: list[dict[str, Any]] = field(default_factory=list)
    coco_annotations: list[dict[str, Any]] = field(default_factory=list)


@dataclass
class _Frame:
    """What one keypoint has received so far."""

    objects: list[tuple[int, MeshObject]] = field(default_factory=list)  # (gt_id, object) in scene_gt
    colors: bool = False
    depth: bool = False
    masks_done: bool = False
    valid: np.ndarray | None = None  # depth PNG > 0, until px_count_valid is computed
    full_masks: list[np.ndarray] | None = None  # waiting for depth (px_count_valid)
    info: list[dict[str, Any]] = field(default_factory=list)


class BopWriter:
    """Frame sink writing a BOP dataset (see the module documentation).

    ``select`` returns the annotated objects (called when the first renderer starts; default: every
    object of ``scene``). Needs per keypoint ``colors``, ``depth`` and ``instance_segmaps``.
    """

    def __init__(self, output_dir: str | Path, scene: Scene, select: Callable[[], list[MeshObject]] | None = None, *,
                 dataset: str = "", append: bool = False, depth_scale: float = 1.0, color_file_format: str = "PNG",
                 jpg_quality: int = 95, frames_per_chunk: int = 1000, annotation_unit: str = "mm",
                 save_world2cam: bool = True, calc_mask_info_coco: bool = True, ignore_dist_thres: float = 100.0,
                 log: Callable[[str], None] | None = None) -> None:
        if not depth_scale > 0:
            raise InputError(f"depth_scale must be > 0, got {depth_scale}")
        if frames_per_chunk < 1:
            raise InputError(f"frames_per_chunk must be >= 1, got {frames_per_chunk}")
        if annotation_unit not in ANNOTATION_UNITS:
            raise InputError(f"annotation_unit must be one of {list(ANNOTATION_UNITS)}, got {annotation_unit!r}")
        if color_file_format not in COLOR_FORMATS:
            raise InputError(f"color_file_format must be one of {COLOR_FORMATS}, got {color_file_format!r}")
        self.scene, self.select = scene, select
        self.output_dir = prepare_output_dir(Path(output_dir))
        self.dataset_dir = confined_path(self.output_dir, dataset, "dataset") if dataset else self.output_dir
        self.dataset_name = dataset or self.output_dir.resolve().name
        self.chunks_dir = self.dataset_dir / "train_pbr"
        for folder in (self.dataset_dir, self.chunks_dir):
            if folder.exists() and not folder.is_dir():
                raise InputError(f"'{folder}' exists and is not a directory")
        self.depth_scale, self.frames_per_chunk = float(depth_scale), int(frames_per_chunk)
        self.unit = ANNOTATION_UNITS[annotation_unit]
        self.extension = ".png" if color_file_format == "PNG" else ".jpg"
        self.jpg_quality, self.save_world2cam = int(jpg_quality), save_world2cam
        self.calc_mask_info_coco, self.ignore_dist_thres = calc_mask_info_coco, float(ignore_dist_thres)
        self.log = log or (lambda message: None)
        self.start_chunk, self.start_frame = 0, 0
        self.chunks: dict[int, _Chunk] = {}
        self._unlock = hold_output_lock(self.output_dir)  # ids and chunks stay ours until finalize/abort
        try:
            self._find_start(append)
        except BaseException:
            self._unlock()
            raise
        self.count = 0
        self.camera: dict[str, np.ndarray] = {}
        self.depth_background = float("inf")
        self.objects: list[MeshObject] | None = None
        self.intrinsics: Intrinsics | None = None
        self.frames: dict[int, _Frame] = {}
        self.too_far = 0
        self._staged = StagedFiles()
        self._amodal = AmodalMasks(scene)

    # ------------------------------------------------------------------ layout
    def _existing_chunks(self) -> list[int]:
        if not self.chunks_dir.is_dir():
            return []
        return sorted(int(p.name) for p in self.chunks_dir.iterdir() if p.is_dir() and p.name.isdigit())

    def _find_start(self, append: bool) -> None:
        existing = self._existing_chunks()
        if not existing:
            return
        if not append:
            raise InputError(f"'{self.chunks_dir}' already holds BOP chunks {existing[:3]}...; set "
                             "append_to_existing_output: true to add to them, or choose another output_dir")
        last = existing[-1]
        chunk_dir = self.chunks_dir / f"{last:06d}"
        gt = load_bop_json(chunk_dir / "scene_gt.json")
        next_frame = max(gt, default=-1) + 1
        if next_frame % self.frames_per_chunk == 0 and next_frame > 0:
            self.start_chunk, self.start_frame = last + 1, 0
            return
        self.start_chunk, self.start_frame = last, next_frame
        chunk = _Chunk(camera=load_bop_json(chunk_dir / "scene_camera.json"), gt=gt)
        if self.calc_mask_info_coco:
            chunk.info = load_bop_json(chunk_dir / "scene_gt_info.json")
            chunk.coco = load_coco_json(chunk_dir / "scene_gt_coco.json")
        self.chunks[last] = chunk

    def position(self, index: int) -> tuple[int, int]:
        """(chunk id, image id) of keypoint ``index`` of this run."""
        frame = self.start_frame + index
        return self.start_chunk + frame // self.frames_per_chunk, frame % self.frames_per_chunk

    def _chunk(self, chunk_id: int) -> _Chunk:
        return self.chunks.setdefault(chunk_id, _Chunk())

    def _path(self, index: int, folder: str, name: str) -> Path:
        chunk_id, _ = self.position(index)
        directory = self.chunks_dir / f"{chunk_id:06d}" / folder
        self._staged.make_dir(directory)
        return directory / name

    # ------------------------------------------------------------------ FrameSink
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
        self.intrinsics = self.scene.camera.intrinsics
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
        _, im_id = self.position(index)
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
            self._masks(index, np.asarray(values["instance_segmaps"]), frame)
        if frame.valid is not None and frame.full_masks is not None:
            for record, mask in zip(frame.info, frame.full_masks, strict=True):
                record["px_count_valid"] = int(np.count_nonzero(frame.valid & mask))
            frame.valid = frame.full_masks = None

    def end(self) -> None:
        """Nothing to flush: files are staged as keypoints arrive."""

    # ------------------------------------------------------------------ per keypoint
    def _pose_records(self, index: int) -> _Frame:
        """scene_camera and scene_gt entries of keypoint ``index`` (poses only: no image needed)."""
        assert self.objects is not None
        chunk_id, im_id = self.position(index)
        chunk = self._chunk(chunk_id)
        world2cam = np.linalg.inv(self.camera["cam2world"][index])
        entry: dict[str, Any] = {"cam_K": self.camera["cam_K"][index].ravel().tolist(), "depth_scale": self.depth_scale}
        if self.save_world2cam:
            entry["cam_R_w2c"] = world2cam[:3, :3].ravel().tolist()
            entry["cam_t_w2c"] = (world2cam[:3, 3] * self.unit).tolist()
        chunk.camera[im_id] = entry
        frame, gts = _Frame(), []
        for obj in self.objects:
            obj2cam = world2cam @ obj.local2world
            if np.linalg.norm(obj2cam[:3, 3]) > self.ignore_dist_thres:
                self.log(f"BOP: object '{obj.name}' is more than {self.ignore_dist_thres} m from the camera at "
                         f"keypoint {index}; left out of scene_gt")
                continue
            frame.objects.append((len(gts), obj))
            gts.append({"cam_R_m2c": rigid_rotation(obj2cam[:3, :3], obj.name).ravel().tolist(),
                        "cam_t_m2c": (obj2cam[:3, 3] * self.unit).tolist(), "obj_id": int(obj.category_id)})
        chunk.gt[im_id] = gts
        return frame

    def _masks(self, index: int, instance: np.ndarray, frame: _Frame) -> None:
        """Full and visible masks, scene_gt_info and COCO entries of keypoint ``index``."""
        assert self.intrinsics is not None
        chunk_id, im_id = self.position(index)
        chunk = self._chunk(chunk_id)
        cam2world = self.camera["cam2world"][index]
        height, width = instance.shape
        intr = Intrinsics(self.camera["cam_K"][index], width, height, self.intrinsics.clip_start,
                          self.intrinsics.clip_end)
        visible_counts = np.bincount(instance.ravel(), minlength=max(o.instance_id for o in self.scene.objects) + 1)
        masks = []
        for gt_id, obj in frame.objects:
            full, count_all, box_all = self._amodal.silhouette(obj, cam2world, intr)
            visible = instance == obj.instance_id
            count_visib = int(visible_counts[obj.instance_id])
            ys, xs = np.nonzero(visible)
            info = {"bbox_obj": box_all if count_visib else list(NO_BOX),
                    "bbox_visib": toolkit_box(xs, ys) if count_visib else list(NO_BOX),
                    "px_count_all": count_all, "px_count_valid": 0, "px_count_visib": count_visib,
                    "visib_fract": count_visib / count_all if count_all else 0.0}
            frame.info.append(info)
            masks.append(full)
            name = f"{im_id:06d}_{gt_id:06d}.png"
            self._staged.add(self._path(index, "mask", name), png_bytes(full.astype(np.uint8) * 255))
            self._staged.add(self._path(index, "mask_visib", name), png_bytes(visible.astype(np.uint8) * 255))
            if count_visib and full.any():
                chunk.coco_annotations.append({
                    "image_id": im_id, "category_id": int(obj.category_id), "iscrowd": 0, "area": count_visib,
                    "bbox": bbox_of(full), "segmentation": rle_uncompressed(visible),
                    "width": width, "height": height, "ignore": bool(info["visib_fract"] < 0.1)})
        chunk.info[im_id] = frame.info
        chunk.coco_images.append({"id": im_id, "file_name": f"rgb/{im_id:06d}{self.extension}",
                                  "width": width, "height": height})
        frame.full_masks, frame.masks_done = masks, True

    # ------------------------------------------------------------------ commit
    def needed_keys(self) -> dict[str, str]:
        """The keys this writer needs, with how to make them."""
        return {k: v for k, v in NEEDED_KEYS.items() if k != "instance_segmaps" or self.calc_mask_info_coco}

    def missing_keys(self) -> list[str]:
        """Needed keys some keypoint never received."""
        frames = [self.frames.get(i, _Frame()) for i in range(self.count)]
        received = {"colors": all(f.colors for f in frames), "depth": all(f.depth for f in frames),
                    "instance_segmaps": all(f.masks_done for f in frames)}
        return [key for key in self.needed_keys() if not received[key]]

    def finalize(self, records: dict[str, Any] | None = None,
                 attributes: dict[str, Any] | None = None) -> list[Path]:
        """Rename every staged file and write the JSON files; returns ``[the dataset folder]``."""
        if self.count == 0:
            raise InputError("no keypoint was rendered before the BOP writer")
        missing = self.missing_keys()
        if missing:
            raise InputError(f"a BOP dataset needs {missing} for every keypoint: "
                             + "; ".join(self.needed_keys()[k] for k in missing))
        if self.too_far:
            self.log(f"BOP: {self.too_far} depth pixel(s) beyond {65535 * self.depth_scale:.0f} mm were written as 0 "
                     "(no depth); raise depth_scale to keep them")
        texts = self._json_texts()
        self._staged.commit()
        for path, text in texts.items():
            write_file(path, text.encode("utf-8"), durable=True)
        self._amodal.release()
        self._unlock()
        return [self.dataset_dir]

    def abort(self) -> None:
        """Delete everything staged (and the folders made for it); existing chunks stay as they were."""
        self._staged.discard()
        self._amodal.release()
        self._unlock()

    def _json_texts(self) -> dict[Path, str]:
        texts: dict[Path, str] = {}
        K = self.camera["cam_K"][0]
        assert self.intrinsics is not None
        camera = {"cx": float(K[0, 2]), "cy": float(K[1, 2]), "depth_scale": self.depth_scale, "fx": float(K[0, 0]),
                  "fy": float(K[1, 1]), "height": self.intrinsics.height, "width": self.intrinsics.width}
        texts[self.dataset_dir / "camera.json"] = json.dumps(camera, sort_keys=True, indent=2)
        categories = sorted({int(o.category_id) for o in self.objects or []})
        for chunk_id, chunk in sorted(self.chunks.items()):
            folder = self.chunks_dir / f"{chunk_id:06d}"
            self._staged.make_dir(folder)
            texts[folder / "scene_camera.json"] = bop_json_text(chunk.camera)
            texts[folder / "scene_gt.json"] = bop_json_text(chunk.gt)
            if not self.calc_mask_info_coco:
                continue
            texts[folder / "scene_gt_info.json"] = bop_json_text(chunk.info)
            coco = chunk.coco or {"info": {"description": f"{self.dataset_name}_train", "contributor": "hybridgen"},
                                  "licenses": [], "categories": [], "images": [], "annotations": []}
            known = {c.get("id") for c in coco["categories"]}
            coco["categories"] = coco["categories"] + [
                {"id": c, "name": str(c), "supercategory": self.dataset_name} for c in categories if c not in known]
            next_id = 1 + max((a.get("id", 0) for a in coco["annotations"]), default=0)
            annotations = [{"id": next_id + i, **a} for i, a in enumerate(chunk.coco_annotations)]
            coco["images"] = coco["images"] + chunk.coco_images
            coco["annotations"] = coco["annotations"] + annotations
            texts[folder / "scene_gt_coco.json"] = json.dumps(coco)
        return texts
