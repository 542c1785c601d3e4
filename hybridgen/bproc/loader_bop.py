"""``bproc.loader.load_bop_objs``, ``load_bop_scene`` and ``load_bop_intrinsics``: BOP datasets as BlenderProc
2.8 loads them (its BopLoader over the bop_toolkit's dataset parameters).

A dataset folder (``<bop_parent>/<name>``) holds ``models[_<model_type>]/obj_<id:06d>.ply`` with
``models_info.json``, ``camera[_<cam_type>].json`` and split folders ``<split>[_<type>]/<scene:06d>/``
(``scene_gt.json``, ``scene_camera.json``). Where ``model_type`` / ``cam_type`` are '' the bop_toolkit's
default of the dataset applies (T-LESS: ``models_cad``, ``camera_primesense.json``, ``test_primesense``;
YCB-V: ``camera_uw.json``, ``train_real``; TUD-L: ``train_render``), falling back to the plain name where that
folder or file is absent (as :mod:`hybridgen.modules.bop_loader`). The object ids are those of
``models_info.json``; the image size is the camera file's ``width`` / ``height``.

Each model is read by :func:`hybridgen.bproc.loader.load_obj` (a PLY: Z up as stored, its vertex colors as the
base color) once per call chain and duplicated after (a duplicate gets copies of the materials, as BlenderProc
does since its issue 590); the last material is named ``bop_<dataset>_vertex_col_material``, the object is
scaled by the model unit (``object_model_unit`` m/dm/cm/mm, or the deprecated ``mm2m``) and gets the custom
properties ``category_id`` (its obj_id), ``model_path``, ``is_bop_object`` and ``bop_dataset_name``. Draws
(``sample_objects``) use Python's ``random.choice``, as BlenderProc.

``load_bop_scene`` replicates a scene: the world is the first image's camera frame; every object of that
image is posed by its ``cam_R_m2c``/``cam_t_m2c``; every image adds a camera pose ``m2w_ref @ inv(m2c_ref)``
(ref: the image's first object) read in ``source_frame`` (default OpenCV's ``[X, -Y, -Z]``) and keys the
objects' poses at that frame. hybridgen keys no intrinsics per frame: the camera keeps the last image's K (a
warning says so when the images' K differ; BlenderProc keys the principal point per frame).
"""
from __future__ import annotations

import json
import os
import random
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..logs import LOGGER
from ..modules.bop_loader import DEFAULT_CAM_TYPE, DEFAULT_MODEL_TYPE, DEFAULT_SPLIT_TYPE
from .types import MeshObject

UNIT_SCALE = {"m": 1.0, "dm": 0.1, "cm": 0.01, "mm": 0.001}
_CACHE: dict[str, MeshObject] = {}
"""The first object loaded from each model file (duplicated for later loads while it is alive)."""


def _dataset(bop_dataset_path: str, call: str) -> tuple[Path, str]:
    root = Path(os.path.normpath(str(bop_dataset_path)))
    if not root.parent.exists():
        raise InputError(f"bproc.loader.{call}: It seems the BOP dataset does not exist under the given path "
                         f"{bop_dataset_path}")
    if not root.is_dir():
        raise InputError(f"bproc.loader.{call}: BOP dataset folder not found: '{root}'")
    return root, root.name


def _first(candidates: list[Path], call: str, what: str) -> Path:
    for path in candidates:
        if path.exists():
            return path
    tried = " or ".join(f"'{p}'" for p in dict.fromkeys(candidates))
    raise InputError(f"bproc.loader.{call}: BOP {what} not found: {tried}")


def _json(path: Path, call: str) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"bproc.loader.{call}: BOP file not found: '{path}'") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"bproc.loader.{call}: cannot read BOP file '{path}': {exc}") from None


def _models_folder(root: Path, name: str, model_type: str, call: str) -> Path:
    chosen = model_type or DEFAULT_MODEL_TYPE.get(name, "")
    candidates = [root / ("models" + (f"_{chosen}" if chosen else ""))]
    if not model_type:
        candidates.append(root / "models")
    return _first(candidates, call, "models folder")


def _camera(root: Path, name: str, cam_type: str, call: str) -> dict[str, Any]:
    chosen = cam_type or DEFAULT_CAM_TYPE.get(name, "")
    candidates = [root / ("camera" + (f"_{chosen}" if chosen else "") + ".json")]
    if not cam_type:
        candidates.append(root / "camera.json")
    camera = _json(_first(candidates, call, "camera file"), call)
    if not isinstance(camera, dict) or not all(isinstance(camera.get(k), (int, float))
                                               for k in ("fx", "fy", "cx", "cy", "width", "height")):
        raise InputError(f"bproc.loader.{call}: the BOP camera file needs numbers fx, fy, cx, cy, width, height")
    return camera


def _split_folder(root: Path, name: str, split: str, cam_type: str, call: str) -> Path:
    split_type = cam_type or DEFAULT_SPLIT_TYPE.get((name, split))
    candidates = [root / (split + (f"_{split_type}" if split_type else ""))]
    if not cam_type:
        candidates.append(root / split)
    for folder in candidates:
        if folder.is_dir():
            return folder
    raise InputError(f"bproc.loader.{call}: Wrong path or {split} split does not exist in {root}")


def _scale(object_model_unit: str, mm2m: bool | None) -> float:
    if object_model_unit not in UNIT_SCALE:
        raise InputError(f"Invalid object model unit: `{object_model_unit}`. Supported are 'm', 'dm', 'cm', 'mm'")
    if mm2m is not None:
        warnings.warn("WARNING: `mm2m` is deprecated, please use `object_model_unit='mm'` instead!")
        return 0.001
    return UNIT_SCALE[object_model_unit]


def _load_mesh(obj_id: int, models: Path, dataset: str, scale: float, call: str) -> MeshObject:
    """One BOP model as a mesh object (module doc)."""
    from .loader_object import load_obj

    path = str(models / f"obj_{int(obj_id):06d}.ply")
    cached = _CACHE.get(path)
    if cached is not None and cached.is_valid():
        obj = cached.duplicate()
        assert isinstance(obj, MeshObject)
        for index, material in enumerate(obj.get_materials()):
            if material is not None:
                obj.set_material(index, material.duplicate())
    else:
        if not os.path.isfile(path):
            raise InputError(f"bproc.loader.{call}: obj_id {obj_id} has no model '{path}'")
        objects = load_obj(path)
        if len(objects) != 1:
            raise InputError(f"bproc.loader.{call}: Loading object from '{path}' returned more than one mesh")
        obj = objects[0]
        _CACHE[path] = obj
    materials = obj.get_materials()
    if materials and materials[-1] is not None:
        materials[-1].set_name(f"bop_{dataset}_vertex_col_material")
    obj.set_scale([scale, scale, scale])
    obj.set_cp("category_id", int(obj_id))
    obj.set_cp("model_path", path)
    obj.set_cp("is_bop_object", True)
    obj.set_cp("bop_dataset_name", dataset)
    return obj


def _object_ids(models: Path, call: str) -> list[int]:
    info = _json(models / "models_info.json", call)
    if not isinstance(info, dict):
        raise InputError(f"bproc.loader.{call}: '{models / 'models_info.json'}' must map object ids to model info")
    return sorted(int(k) for k in info)


def load_bop_objs(bop_dataset_path: str, model_type: str = "", obj_ids: list[int] | None = None,
                  sample_objects: bool = False, num_of_objs_to_sample: int | None = None,
                  obj_instances_limit: int = -1, mm2m: bool | None = None, object_model_unit: str = "m",
                  move_origin_to_x_y_plane: bool = False) -> list[MeshObject]:
    """All, the listed (``obj_ids``) or ``num_of_objs_to_sample`` drawn models of a BOP dataset, at the origin
    (module doc)."""
    call = "load_bop_objs"
    root, name = _dataset(bop_dataset_path, call)
    models = _models_folder(root, name, model_type, call)
    scale = _scale(object_model_unit, mm2m)
    ids = [int(i) for i in obj_ids] if obj_ids else _object_ids(models, call)
    loaded: list[MeshObject] = []
    if sample_objects:
        if num_of_objs_to_sample is None or int(num_of_objs_to_sample) < 0:
            raise InputError(f"bproc.loader.{call}: sample_objects needs num_of_objs_to_sample >= 0")
        count = int(num_of_objs_to_sample)
        if obj_instances_limit != -1 and len(ids) * obj_instances_limit < count:
            raise InputError(f"{bop_dataset_path}'s contains {len(ids)} objects, {count} object where requested to "
                             f"sample with an instances limit of {obj_instances_limit}. Raise the limit amount or "
                             "decrease the requested amount of objects.")
        copies: dict[int, int] = {}
        while len(loaded) < count:
            pick = random.choice(ids)
            if obj_instances_limit == -1 or copies.get(pick, 0) < obj_instances_limit:
                copies[pick] = copies.get(pick, 0) + 1
                loaded.append(_load_mesh(pick, models, name, scale, call))
    else:
        loaded = [_load_mesh(obj_id, models, name, scale, call) for obj_id in ids]
    if move_origin_to_x_y_plane:
        for obj in loaded:
            obj.move_origin_to_bottom_mean_point()
    return loaded


def _pose(instance: dict[str, Any], scale: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = np.asarray(instance["cam_R_m2c"], dtype=np.float64).reshape(3, 3)
    pose[:3, 3] = np.asarray(instance["cam_t_m2c"], dtype=np.float64).reshape(3) * scale
    return pose


def load_bop_scene(bop_dataset_path: str, scene_id: int, model_type: str = "", cam_type: str = "",
                   split: str = "test", source_frame: list[str] | None = None, mm2m: bool | None = None,
                   object_model_unit: str = "m") -> list[MeshObject]:
    """Replicate scene ``scene_id`` of a BOP split: its objects at their poses, one camera pose per image
    (module doc)."""
    from ..config.camera_poses import source_frame_axes
    from .camera import add_camera_pose, set_intrinsics_from_K_matrix

    call = "load_bop_scene"
    root, name = _dataset(bop_dataset_path, call)
    models = _models_folder(root, name, model_type, call)
    camera = _camera(root, name, cam_type, call)
    folder = _split_folder(root, name, split, cam_type, call) / f"{int(scene_id):06d}"
    gt = _json(folder / "scene_gt.json", call)
    cams = _json(folder / "scene_camera.json", call)
    scale = _scale(object_model_unit, mm2m)
    axes = np.eye(4)
    axes[:3, :3] = source_frame_axes(list(source_frame or ["X", "-Y", "-Z"])).T
    width, height = int(camera["width"]), int(camera["height"])
    objects: list[MeshObject] = []
    first: np.ndarray | None = None
    ks = []
    try:
        for image_id in sorted(gt, key=int):
            instances = gt[image_id]
            k = np.asarray(cams[str(image_id)]["cam_K"], dtype=np.float64).reshape(3, 3)
            ref = _pose(instances[0], scale)
            if first is None:  # world = this first camera's frame
                first = ref
                for instance in instances:
                    obj = _load_mesh(int(instance["obj_id"]), models, name, scale, call)
                    obj.set_local2world_mat(_pose(instance, scale))
                    obj.set_scale([scale, scale, scale])
                    objects.append(obj)
            cam2world = first @ np.linalg.inv(ref) @ axes  # Blender camera axes
            set_intrinsics_from_K_matrix(k, width, height)
            ks.append(k)
            frame = add_camera_pose(cam2world)
            for obj in objects:
                obj.set_location(obj.get_location(), frame)
                obj.set_rotation_euler(obj.get_rotation_euler(), frame)
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise InputError(f"bproc.loader.{call}: malformed BOP scene files in '{folder}' (scene_gt.json / "
                         f"scene_camera.json): {type(exc).__name__}: {exc}") from None
    if any(not np.allclose(k, ks[-1]) for k in ks):
        LOGGER.warning("bproc.loader.load_bop_scene: the images of scene %s have different cam_K; hybridgen keys "
                       "no intrinsics per frame, every frame renders with the last image's K", scene_id)
    return objects


def load_bop_intrinsics(bop_dataset_path: str, split: str = "test", cam_type: str = "") -> tuple[np.ndarray, int,
                                                                                                  int]:
    """Set the camera to the dataset's K and image size; returns ``(K, width, height)``. T-LESS images are
    crops: its principal point becomes the image centre, as in BlenderProc."""
    from .camera import set_intrinsics_from_K_matrix

    call = "load_bop_intrinsics"
    root, name = _dataset(bop_dataset_path, call)
    camera = _camera(root, name, cam_type, call)
    width, height = int(camera["width"]), int(camera["height"])
    k = np.array([[camera["fx"], 0.0, camera["cx"]], [0.0, camera["fy"], camera["cy"]], [0.0, 0.0, 1.0]])
    if name == "tless":
        k[0, 2], k[1, 2] = width / 2, height / 2
    set_intrinsics_from_K_matrix(k, width, height)
    return k, width, height
