"""``loader.BopLoader``: objects (and optionally a whole scene) of a BOP dataset, as BlenderProc loads them.

A BOP dataset folder (``bop_dataset_path``, e.g. ``.../bop/lm``) holds ``models[_<model_type>]/obj_<id:06d>.ply``
(millimetres), ``models*/models_info.json``, ``camera[_<cam_type>].json`` (fx, fy, cx, cy, width, height) and
split folders ``<split>[_<sensor>]/<scene_id:06d>/scene_gt.json`` + ``scene_camera.json``. Where a type is ''
the dataset's bop_toolkit default applies (T-LESS: ``models_cad``, ``camera_primesense.json``,
``test_primesense``; YCB-V: ``camera_uw.json``, ``train_real``; TUD-L: ``train_render``), falling back to the
plain name when that folder or file is absent (a type the config names has no fallback).

- Without ``scene_id``: loads ``obj_ids`` (default: every model) - or, with ``sample_objects``,
  ``num_of_objs_to_sample`` random draws among them (at most ``obj_instances_limit`` copies each) - at the
  origin, and sets the camera intrinsics from the dataset's camera file (for ``tless``, as BlenderProc, with
  the principal point at ``(width / 2, height / 2)``).
- With ``scene_id``: replicates the scene as BlenderProc does. The world is the first image's camera frame
  (OpenCV axes); every object gets its ``cam_R_m2c``/``cam_t_m2c`` of that image; every image of the scene
  becomes a keypoint whose cam2world is ``m2w_ref @ inv(m2c_ref)`` (ref: the image's first object), read in
  the ``source_frame`` (default ``[X, -Y, -Z]``: an OpenCV camera, see docs/conventions.md section 1). Each
  image renders with its own ``cam_K`` of ``scene_camera.json`` (``Camera.intrinsics_per_keypoint`` when they
  differ; BlenderProc keyframes the principal point per frame).

Objects are named as Blender's PLY importer names them (``obj_000001``, clashes ``.001``), get
``category_id`` = their BOP obj_id and the attribute ``bop_dataset_name`` (the folder's name), which
writer.BopWriter uses. ``mm2m`` scales models and poses from millimetres to metres. A model's texture
(ycbv-style ``comment TextureFile`` with ``texture_u``/``texture_v``) becomes its base-colour texture; vertex
colours are the base colour per vertex in color and albedo (decoded from sRGB, as Blender's colour attribute
node that BlenderProc links to Base Color); ``base_color`` keeps their mean code / 255 as a single summary.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..config.blenderproc import custom_properties
from ..config.camera_poses import source_frame_axes
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.mesh_loader import load_objects
from ..run.context import RunContext
from ..scene.camera import Intrinsics
from ..scene.frames import BLENDER_TO_OPENCV
from .base import Module, Role
from .obj_loader import add_with_blender_names


def _read_json(path: Path, key: str) -> Any:
    """Parse a BOP JSON file; a missing or broken one is a :class:`ConfigError` on ``key`` naming the file."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"BOP file not found: '{path}'", key=key) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ConfigError(f"cannot read BOP file '{path}': {exc}", key=key) from None


# bop_toolkit's per-dataset defaults (dataset_params.py), which BlenderProc gets through it: the camera file
# and models folder used when cam_type / model_type are '', and the sensor suffix of split folders.
DEFAULT_CAM_TYPE = {"tless": "primesense", "ycbv": "uw"}
DEFAULT_MODEL_TYPE = {"tless": "cad"}
DEFAULT_SPLIT_TYPE = {("tless", "train"): "primesense", ("tless", "test"): "primesense",
                      ("tudl", "train"): "render", ("ycbv", "train"): "real"}


def _first_existing(candidates: list[Path], key: str, what: str) -> Path:
    """The first of ``candidates`` that exists, else a :class:`ConfigError` on ``key`` naming them all."""
    for path in candidates:
        if path.exists():
            return path
    tried = " or ".join(f"'{p}'" for p in dict.fromkeys(candidates))
    raise ConfigError(f"BOP {what} not found: {tried}", key=key)


def _pose(rotation: Any, translation: Any, scale: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
    pose[:3, 3] = np.asarray(translation, dtype=np.float64).reshape(3) * scale
    return pose


@register_module("loader.BopLoader")
class BopLoader(Module):
    """Loads BOP models (sampled, listed or all) or replicates a BOP scene with its cameras."""

    role = Role.LOADER

    params = (
        Param("bop_dataset_path", "path", doc="the dataset's folder, e.g. <bop>/lm"),
        Param("model_type", "str", "", doc="models folder suffix: '' (models), cad, eval, reconst ..."),
        Param("cam_type", "str", "", doc="camera file suffix: '' (camera.json) or e.g. primesense"),
        Param("split", "str", "test", doc="split folder for scene replication (test, val, train ...)"),
        Param("scene_id", "int", -1, doc="scene to replicate (-1: load objects only)"),
        Param("obj_ids", "list", [], doc="BOP object ids to load (default: every model)"),
        Param("sample_objects", "bool", False, doc="draw num_of_objs_to_sample objects among obj_ids"),
        Param("num_of_objs_to_sample", "int|null", None, doc="how many objects to draw"),
        Param("obj_instances_limit", "int", -1, doc="at most this many copies of one model (-1: no limit)"),
        Param("move_origin_to_x_y_plane", "bool", False, doc="put each model's origin at the centre of its "
              "bottom (for filler objects; not for pose annotations)"),
        Param("source_frame", "list", ["X", "-Y", "-Z"], doc="axes of the scene's camera poses in Blender's "
              "camera axes; the default is OpenCV's"),
        Param("mm2m", "bool", False, doc="models and poses from millimetres to metres"),
        Param("add_properties", "dict", {}, doc="cp_* custom properties of every loaded object"),
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        root = Path(cfg["bop_dataset_path"])
        if not root.is_dir():
            raise ConfigError(f"BOP dataset folder not found: '{root}'", key="bop_dataset_path")
        scale = 0.001 if cfg["mm2m"] else 1.0
        model_type = cfg["model_type"] or DEFAULT_MODEL_TYPE.get(root.name, "")
        models = _first_existing([root / ("models" + (f"_{model_type}" if model_type else ""))]
                                 + ([root / "models"] if not cfg["model_type"] else []), "model_type", "models folder")
        cam_type = cfg["cam_type"] or DEFAULT_CAM_TYPE.get(root.name, "")
        camera = _read_json(_first_existing([root / ("camera" + (f"_{cam_type}" if cam_type else "") + ".json")]
                                            + ([root / "camera.json"] if not cfg["cam_type"] else []),
                                            "cam_type", "camera file"), "cam_type")
        if not all(isinstance(camera.get(k), (int, float)) for k in ("fx", "fy", "cx", "cy", "width", "height")):
            raise ConfigError("the BOP camera file needs numbers fx, fy, cx, cy, width, height", key="cam_type")
        labels: dict[str, Any] = {}
        custom_properties(cfg["add_properties"], labels)
        if cfg["scene_id"] < 0:
            ids = self._object_ids(context, models)
            poses = [np.eye(4)] * len(ids)
            width, height = int(camera["width"]), int(camera["height"])
            cx, cy = camera["cx"], camera["cy"]
            if root.name == "tless":  # as BlenderProc: T-LESS images are crops, principal point = image centre
                cx, cy = width / 2, height / 2
            context.scene.camera.intrinsics = Intrinsics(
                [[camera["fx"], 0, cx], [0, camera["fy"], cy], [0, 0, 1]], width, height)
        else:
            ids, poses = self._replicate(context, root, camera, scale)
        for obj_id, pose in zip(ids, poses):
            path = models / f"obj_{int(obj_id):06d}.ply"
            objects = load_objects(path, category_id=int(obj_id), up_axis="auto",
                                   attributes={"bop_dataset_name": root.name, **labels.get("attributes", {})},
                                   local2world=pose @ np.diag([scale, scale, scale, 1.0]))
            for obj in objects:
                if "category_id" in labels:
                    obj.category_id = labels["category_id"]
                if cfg["move_origin_to_x_y_plane"]:
                    self._origin_to_bottom(obj)
            add_with_blender_names(context, objects, renamed=True)

    def _object_ids(self, context: RunContext, models: Path) -> list[int]:
        cfg = self.config
        info_path = models / "models_info.json"
        ids = [int(i) for i in cfg["obj_ids"]]
        if ids and not info_path.is_file():  # listed ids need no models_info.json, only their model files
            missing = [i for i in ids if not (models / f"obj_{i:06d}.ply").is_file()]
            if missing:
                raise ConfigError(f"obj_id {missing[0]} has no model '{models / f'obj_{missing[0]:06d}.ply'}'",
                                  key="obj_ids")
            return self._sample(context, ids)
        known = sorted(int(k) for k in _read_json(info_path, "model_type"))
        unknown = [i for i in ids if i not in known]
        if unknown:
            raise ConfigError(f"obj_id {unknown[0]} is not a model of '{info_path}' (it lists {known})",
                              key="obj_ids")
        return self._sample(context, ids or known)

    def _sample(self, context: RunContext, ids: list[int]) -> list[int]:
        """``ids`` as they are, or with ``sample_objects`` the drawn ones (with replacement, instance limit)."""
        cfg = self.config
        if not cfg["sample_objects"]:
            return ids
        count = cfg["num_of_objs_to_sample"]
        if count is None or count < 1:
            raise ConfigError("sample_objects needs num_of_objs_to_sample >= 1", key="num_of_objs_to_sample")
        limit = cfg["obj_instances_limit"]
        if limit != -1 and len(set(ids)) * limit < count:
            raise ConfigError(f"{len(set(ids))} models with at most {limit} copies each cannot give {count} "
                              "objects", key="obj_instances_limit")
        drawn: list[int] = []
        copies: dict[int, int] = {}
        while len(drawn) < count:
            pick = ids[int(context.rng.integers(len(ids)))]
            if limit == -1 or copies.get(pick, 0) < limit:
                copies[pick] = copies.get(pick, 0) + 1
                drawn.append(pick)
        return drawn

    def _replicate(self, context: RunContext, root: Path, camera: dict[str, Any],
                   scale: float) -> tuple[list[int], list[np.ndarray]]:
        cfg = self.config
        split_type = DEFAULT_SPLIT_TYPE.get((root.name, cfg["split"]))
        scene_dir = _first_existing(
            [root / (cfg["split"] + (f"_{split_type}" if split_type else "")) / f"{cfg['scene_id']:06d}",
             root / cfg["split"] / f"{cfg['scene_id']:06d}"], "scene_id", "scene folder")
        gt = _read_json(scene_dir / "scene_gt.json", "scene_id")
        cams = _read_json(scene_dir / "scene_camera.json", "scene_id")
        if not gt:
            raise ConfigError(f"'{scene_dir / 'scene_gt.json'}' lists no image", key="scene_id")
        try:
            return self._scene_poses(context, gt, cams, camera, scale)
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            raise ConfigError(f"malformed BOP scene files in '{scene_dir}' (scene_gt.json / scene_camera.json): "
                              f"{type(exc).__name__}: {exc}", key="scene_id") from None

    def _scene_poses(self, context: RunContext, gt: dict[str, Any], cams: dict[str, Any], camera: dict[str, Any],
                     scale: float) -> tuple[list[int], list[np.ndarray]]:
        """Object ids and model-to-world poses of the first image; one keypoint per image (see module doc)."""
        cfg = self.config
        axes = np.eye(4)
        axes[:3, :3] = source_frame_axes(cfg["source_frame"]).T
        first = None
        ids: list[int] = []
        poses: list[np.ndarray] = []
        ks = []
        for image_id in sorted(gt, key=int):
            instances = gt[image_id]
            ref = _pose(instances[0]["cam_R_m2c"], instances[0]["cam_t_m2c"], scale)
            if first is None:  # world = this first camera's frame
                first = ref
                ids = [int(inst["obj_id"]) for inst in instances]
                poses = [_pose(inst["cam_R_m2c"], inst["cam_t_m2c"], scale) for inst in instances]
            cam2world = first @ np.linalg.inv(ref)  # the given (source-frame) camera
            context.scene.camera.add_keypoint(cam2world @ axes @ BLENDER_TO_OPENCV)
            ks.append(np.asarray(cams[str(image_id)]["cam_K"], dtype=np.float64).reshape(3, 3))
        intrinsics = [Intrinsics(k, int(camera["width"]), int(camera["height"])) for k in ks]
        cameras = context.scene.camera
        if any(not np.array_equal(k, ks[0]) for k in ks):  # each image renders with its own cam_K
            earlier = len(cameras) - len(ks)
            cameras.intrinsics_per_keypoint = [
                *(cameras.intrinsics_per_keypoint or [cameras.intrinsics] * earlier)[:earlier], *intrinsics]
        cameras.intrinsics = intrinsics[0]
        return ids, poses

    @staticmethod
    def _origin_to_bottom(obj: Any) -> None:
        """Move the mesh so its origin is the centre of its bottom (local frame), keeping its world place."""
        low, high = obj.bounds_local
        shift = np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]])
        obj.vertices = obj.vertices - shift
        obj.local2world = obj.local2world @ np.block([[np.eye(3), shift[:, None]], [np.zeros((1, 3)), 1.0]])
