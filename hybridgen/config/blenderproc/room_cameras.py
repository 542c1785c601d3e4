"""Key translation of BlenderProc's room camera samplers and of the Replica modules of its v1.0 form.

- ``camera.Front3DCameraSampler`` / ``camera.ReplicaCameraSampler`` (v1.12 form, ``cam_poses``): as
  ``camera.CameraSampler`` (module-level novelty checks into every entry ...), plus: ``intrinsics.pixel_aspect_x``
  / ``pixel_aspect_y`` become the ``cam_K`` Blender computes (:func:`pixel_aspect_intrinsics`); ``clip_start`` /
  ``clip_end`` inside a pose entry, which BlenderProc 1.12 does not read there, are dropped with a notice.
- ``camera.ReplicaCameraSampler`` of v1.0 (no ``cam_poses``): ``sample_amount`` (25) cameras at BlenderProc
  1.0's fixed height 1.55 m above a floor height, Euler angles drawn in degrees from ``rotation_range_x``
  (78.6901 deg), ``rotation_range_y`` (0) and ``rotation_range_z`` (a full turn), ``max_tries_per_room`` tries,
  the height list of ``resources/replica-dataset/height_levels``. BlenderProc 1.0 checks proximity with a
  1 rad field of view but renders with its default 0.691111 rad: hybridgen checks what it renders.
- ``loader.PlyLoader`` with ``is_replica_object`` (v1.0) is ``loader.ReplicaLoader``; v1.0's
  ``manipulators.FloorExtractor`` with ``obj_name`` splits that object's floor off as ``floor``.
"""
from __future__ import annotations

import math
from typing import Any

from ...errors import ConfigError
from .common import Note, pop_ignored
from .objects import camera_sampler, loader, passthrough

V1_CAMERA_HEIGHT = 1.55
"""m above the floor: BlenderProc 1.0's ReplicaCameraSampler height (its SUNCG camera height)."""
V1_PITCH_DEG = 78.6901
"""BlenderProc 1.0's default camera rotation about x (deg): 11.3 deg below the horizon."""


def pixel_aspect_intrinsics(intrinsics: dict[str, Any], note: Note, key: str = "intrinsics") -> dict[str, Any]:
    """``fov`` + ``pixel_aspect_x/y`` -> the ``cam_K`` Blender gives that camera: the field of view spans the
    side whose aspect-scaled size is larger (sensor fit AUTO); ``fy = fx * pixel_aspect_x / pixel_aspect_y``."""
    if "pixel_aspect_x" not in intrinsics and "pixel_aspect_y" not in intrinsics:
        return intrinsics
    out = dict(intrinsics)
    aspect_x, aspect_y = float(out.pop("pixel_aspect_x", 1.0)), float(out.pop("pixel_aspect_y", 1.0))
    if "cam_K" in out:
        note("ignored next to cam_K (as BlenderProc)", f"{key}.pixel_aspect_x")
        return out
    if aspect_x <= 0 or aspect_y <= 0:
        raise ConfigError(f"pixel aspect must be positive, got {aspect_x} x {aspect_y}", key=f"{key}.pixel_aspect_x")
    width, height = int(out.get("resolution_x", 512)), int(out.get("resolution_y", 512))
    fov = float(out.pop("fov", 0.691111))
    ratio = aspect_y / aspect_x
    view = width if aspect_x * width >= aspect_y * height else ratio * height
    fx = view / (2.0 * math.tan(fov / 2.0))
    out["cam_K"] = [fx, 0.0, (width - 1) / 2.0, 0.0, fx / ratio, (height - 1) / 2.0, 0.0, 0.0, 1.0]
    return out


def room_sampler(name: str) -> Any:
    """The translator of ``camera.Front3DCameraSampler`` / ``camera.ReplicaCameraSampler``."""

    def translate(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
        if name == "camera.ReplicaCameraSampler" and "cam_poses" not in config:
            config = _replica_v1(config, note)
        if isinstance(config.get("is_replica_object"), str):  # v1.0 writes booleans as strings
            config = {**config, "is_replica_object": _truthy(config["is_replica_object"])}
        [(_, cfg)] = camera_sampler(config, note)
        if isinstance(cfg.get("intrinsics"), dict):
            cfg["intrinsics"] = pixel_aspect_intrinsics(cfg["intrinsics"], note)
        for i, entry in enumerate(cfg.get("cam_poses") or []):
            if isinstance(entry, dict):
                for clip in ("clip_start", "clip_end"):
                    pop_ignored(entry, clip, lambda m, k, i=i: note(m, f"cam_poses[{i}].{k}"),
                                "BlenderProc 1.12 reads the clip range from intrinsics only")
        return [(name, cfg)]

    return translate


def _truthy(value: Any) -> bool:
    """BlenderProc's ``get_bool`` of a value v1.0 configs often write as a string ("True")."""
    return str(value).strip().lower() in ("true", "1", "yes")


def _degrees_range(config: dict[str, Any], key: str, default: list[float] | None) -> list[float] | None:
    value = config.pop(key, default)
    if value is None or (isinstance(value, list) and len(value) != 2):
        return None  # BlenderProc 1.0: anything but [min, max] is a full turn
    return [math.radians(float(v)) for v in value]


def _replica_v1(config: dict[str, Any], note: Note) -> dict[str, Any]:
    """v1.0's ReplicaCameraSampler keys in the v1.12 form."""
    cfg = dict(config)
    for key in ("positon_range_x", "positon_range_y", "position_range_x", "position_range_y"):
        if key in cfg:
            raise ConfigError("a position range inside the scene's bounding box is not supported; the cameras "
                              "are drawn over the whole scene", key=key)
    pop_ignored(cfg, "positon_range_z", note, "BlenderProc 1.0 places its Replica cameras 1.55 m above a floor "
                "height whatever this says")
    pop_ignored(cfg, "near_clipping", note, "BlenderProc 1.0 does not read it (clip range 0.1..1000 m)")
    pop_ignored(cfg, "min_dist_to_obstacle", note, "BlenderProc 1.0 checks proximity_checks only")
    pop_ignored(cfg, "cams_per_square_meter", note, "BlenderProc 1.0's Replica sampler uses sample_amount")
    ranges = [_degrees_range(cfg, "rotation_range_x", [V1_PITCH_DEG, V1_PITCH_DEG]),
              _degrees_range(cfg, "rotation_range_y", [0.0, 0.0]), _degrees_range(cfg, "rotation_range_z", None)]
    low = [r[0] if r else 0.0 for r in ranges]
    high = [r[1] if r else 2 * math.pi for r in ranges]
    entry: dict[str, Any] = {"number_of_samples": cfg.pop("sample_amount", 25),
                             "location": [0.0, 0.0, V1_CAMERA_HEIGHT],
                             "rotation": {"value": {"provider": "sampler.Uniform3d", "min": low, "max": high}}}
    for key in ("proximity_checks", "sqrt_number_of_rays"):
        if key in cfg:
            entry[key] = cfg.pop(key)
    intrinsics = {k: cfg.pop(k) for k in ("resolution_x", "resolution_y", "pixel_aspect_x") if k in cfg}
    if "max_tries_per_room" in cfg:
        cfg["max_tries"] = cfg.pop("max_tries_per_room")
    cfg.update({"intrinsics": intrinsics, "cam_poses": [entry], "height_levels": "resources/replica-dataset/"
                "height_levels"})
    return cfg


def ply_loader(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """v1.0's ``loader.PlyLoader``: with ``is_replica_object`` the Replica scene (loader.ReplicaLoader)."""
    if not _truthy(config.get("is_replica_object", False)):
        return loader("loader.PlyLoader", config, note)
    cfg = {k: v for k, v in config.items() if k != "is_replica_object"}
    pop_ignored(cfg, "use_ambient_occlusion", note, "Replica's baked AO; hybridgen path-traces occlusion")
    if "use_smooth_shading" in cfg:
        cfg["use_smooth_shading"] = _truthy(cfg["use_smooth_shading"])
    return [("loader.ReplicaLoader", cfg)]


def floor_extractor(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """``manipulators.FloorExtractor`` (v1.0): ``obj_name``'s floor becomes the object ``floor``."""
    if "obj_name" not in config:
        return passthrough("object.FloorExtractor", "selector")(config, note)
    cfg = dict(config)
    cfg["selector"] = {"conditions": {"name": str(cfg.pop("obj_name"))}}
    cfg.setdefault("name_for_split_obj", "floor")
    for key in ("is_replica_object", "data_set_name", "height_list_path"):
        pop_ignored(cfg, key, note, "BlenderProc 1.0 takes the faces near each listed floor height; hybridgen "
                    "the faces at the lowest upward level (the same for one-level scenes)")
    return [("object.FloorExtractor", cfg)]
