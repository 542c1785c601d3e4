"""Key translation of the modules that load, build, place and simulate objects (loaders, BasicMeshInitializer,
ObjectReplacer, pose samplers, CameraLoader, PhysicsPositioning)."""
from __future__ import annotations

from typing import Any, Callable

from ...errors import ConfigError
from .common import Note, custom_properties, pop_ignored, shaded, take_shading
from .selectors import selector


_BLENDER_PRIMITIVES = {"plane": ("plane", "Plane"), "cube": ("cube", "Cube"), "uvsphere": ("sphere", "Sphere"),
                       "icosphere": ("sphere", "Icosphere"), "cylinder": ("cylinder", "Cylinder"),
                       "cone": ("cone", "Cone"), "torus": ("torus", "Torus")}


def mesh_initializer(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """``constructor.BasicMeshInitializer``: Blender's primitives (size 2: radius 1, edge 2) as PrimitiveLoader."""
    meshes = config.get("meshes_to_add")
    if not isinstance(meshes, list) or not meshes:
        raise ConfigError("must be a non-empty list of {type, name, location, rotation, scale}",
                          key="meshes_to_add")
    out = []
    for i, mesh in enumerate(meshes):
        where = f"meshes_to_add[{i}]"
        if not isinstance(mesh, dict):
            raise ConfigError("must be a mapping", key=where)
        kind = str(mesh.get("type", "")).lower()
        if kind not in _BLENDER_PRIMITIVES:
            raise ConfigError(f"type {mesh.get('type')!r} is not one of {sorted(_BLENDER_PRIMITIVES)} "
                              "(Blender's circle has no faces; its monkey is not built in)", key=f"{where}.type")
        shape, default_name = _BLENDER_PRIMITIVES[kind]
        cfg: dict[str, Any] = {"shape": shape, "size": 2.0, "name": mesh.get("name", default_name)}
        for key in ("location", "rotation", "scale"):
            if key in mesh:
                cfg[key] = mesh[key]
        if isinstance(mesh.get("add_properties"), dict):
            custom_properties(mesh["add_properties"], cfg)
        if kind == "torus":
            note("Blender's torus has radii 1 and 0.25; hybridgen's torus of size 2 has 0.7 and 0.3", f"{where}.type")
        if "mat_name" in mesh:
            note("the new material keeps hybridgen's default name", f"{where}.mat_name")
        unknown = [k for k in mesh if k not in ("type", "name", "location", "rotation", "scale", "add_properties",
                                                 "mat_name")]
        if unknown:
            raise ConfigError("unknown key; a mesh has type, name, location, rotation, scale, add_properties, "
                              "mat_name", key=f"{where}.{unknown[0]}")
        out.append(("loader.PrimitiveLoader", cfg))
    return out


def bop_loader(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    return shaded([("loader.BopLoader", cfg)], take_shading(cfg))


def replacer(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """``object.ObjectReplacer`` keys -> ``object.ObjectSwapper``'s (scene objects as the pool)."""
    cfg = dict(config)
    renames = {"objects_to_be_replaced": "objects_to_swap", "objects_to_replace_with": "pool_objects",
               "replace_ratio": "swap_probability", "copy_properties": "copy_attributes",
               "relative_rotation_sampler": "relative_rotation"}
    for old, new in renames.items():
        if old in cfg:
            cfg[new] = cfg.pop(old)
    for key in ("objects_to_swap", "pool_objects", "ignore_collision_with"):
        if key in cfg:
            cfg[key] = selector(cfg[key], note, key)
    cfg.setdefault("same_category", False)  # BlenderProc replaces by the selectors alone
    return [("object.ObjectSwapper", cfg)]


def loader(name: str, config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    paths = cfg.pop("paths", None)
    if paths is not None and "path" in cfg:
        raise ConfigError("give path or paths, not both", key="paths")
    props = cfg.pop("add_properties", None)
    if isinstance(props, dict):
        custom_properties(props, cfg)
    if "physics" in cfg:  # v1.0: physics: true marks the objects active for object.PhysicsPositioning
        cfg.setdefault("attributes", {})["physics"] = bool(cfg.pop("physics"))
    for key, why in (("use_smooth_shading", "Blender's shade-smooth; hybridgen uses the file's normals"),
                     ("use_ambient_occlusion", "Replica's baked AO; hybridgen path-traces occlusion"),
                     ("is_replica_object", "a Replica-only flag")):
        pop_ignored(cfg, key, note, why)
    shading = take_shading(cfg)
    entries = [dict(cfg, path=p) for p in paths] if isinstance(paths, list) else [cfg]
    return shaded([("loader.ObjLoader", e) for e in entries], shading)


_SHAPES = {"CONVEX_HULL": "convex_hull", "MESH": "mesh", "CONVEX_DECOMPOSITION": "convex_decomposition",
           "BOX": "box", "SPHERE": "sphere"}


def physics(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    if "solver_iters" in cfg:
        cfg["solver_iterations"] = cfg.pop("solver_iters")
    if "substeps_per_frame" in cfg:
        value = cfg.pop("substeps_per_frame")
        note(f"Blender's {value} substeps per 1/24 s frame are about {max(1, round(value * 240 / 24 / 10))}"
             " per hybridgen step of 1/240 s; hybridgen picks substeps from object sizes (substeps: null)",
             "substeps_per_frame")
    if isinstance(cfg.get("collision_shape"), str):
        cfg["collision_shape"] = _SHAPES.get(cfg["collision_shape"].upper(), cfg["collision_shape"])
        if cfg["collision_shape"] == "mesh":  # Blender simulates moving triangle meshes; Bullet here cannot
            cfg["collision_shape"] = "convex_decomposition"
            cfg.setdefault("passive_collision_shape", "mesh")
            note("moving objects collide as a convex decomposition (CoACD) of their mesh, resting ones as the "
                 "exact mesh", "collision_shape")
    for key in ("mass_scaling", "mass_factor"):
        pop_ignored(cfg, key, note, "hybridgen derives mass from the collision volume x density (key 'density')")
    pop_ignored(cfg, "steps_per_sec", note, "hybridgen steps at time_step")
    return [("object.PhysicsPositioning", cfg)]


def camera_loader(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    defaults = cfg.get("default_cam_param")
    if isinstance(defaults, dict):  # v1.0 puts intrinsics (fov, resolution) among the pose defaults
        intrinsic_keys = ("fov", "resolution_x", "resolution_y", "cam_K", "clip_start", "clip_end")
        moved = {k: defaults[k] for k in intrinsic_keys if k in defaults}
        if moved:
            cfg["default_cam_param"] = {k: v for k, v in defaults.items() if k not in moved}
            cfg["intrinsics"] = {**moved, **(cfg.get("intrinsics") or {})}
    poses = cfg.get("cam_poses")
    if isinstance(poses, list):  # BlenderProc reads location/rotation/cam2world_matrix and skips other keys
        cfg["cam_poses"] = [_read_pose_keys(entry, i, note) if isinstance(entry, dict) else entry
                            for i, entry in enumerate(poses)]
    return [("camera.CameraLoader", cfg)]


_POSE_KEYS = ("location", "rotation", "cam2world_matrix", "source_frame")


def _read_pose_keys(entry: dict[str, Any], index: int, note: Note) -> dict[str, Any]:
    """A cam_poses entry without the keys BlenderProc's CameraLoader does not read (e.g. ``rotation_euler``,
    where it reads ``rotation: {value}``), each reported."""
    kept = dict(entry)
    for key in [k for k in entry if k not in _POSE_KEYS]:
        pop_ignored(kept, key, lambda m, k: note(m, f"cam_poses[{index}].{k}"),
                    "BlenderProc's CameraLoader does not read this key (a pose has location, rotation: "
                    "{value, format}, cam2world_matrix)")
    return kept


_MODULE_LEVEL_CHECKS = ("check_pose_novelty_rot", "check_pose_novelty_translation", "min_var_diff_rot",
                        "min_var_diff_translation")
"""CameraSampler keys BlenderProc reads once for the module (hybridgen: per cam_poses entry)."""


def camera_sampler(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """``camera.CameraSampler``: module-level novelty checks go into every entry; an entry's ``max_tries`` is
    the module's (BlenderProc counts tries per interest-score threshold too)."""
    cfg = dict(config)
    shared = {k: cfg.pop(k) for k in _MODULE_LEVEL_CHECKS if k in cfg}
    entries = cfg.get("cam_poses")
    if isinstance(entries, list):
        out = []
        for entry in entries:
            if not isinstance(entry, dict):
                out.append(entry)
                continue
            entry = {**shared, **entry}
            if "max_tries" in entry:
                cfg["max_tries"] = max(int(entry.pop("max_tries")), int(cfg.get("max_tries", 0)))
            out.append(entry)
        cfg["cam_poses"] = out
    return [("camera.CameraSampler", cfg)]


def pose_sampler(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    if "objects_to_sample" in cfg:
        cfg["objects_to_sample"] = selector(cfg["objects_to_sample"], note, "objects_to_sample")
    else:  # v1.0 PositionSampler / BlenderProc default: every object with physics... every mesh
        cfg["objects_to_sample"] = {"conditions": {}}
    return [("object.ObjectPoseSampler", cfg)]


def passthrough(name: str, *selector_keys: str) -> Callable[[dict[str, Any], Note],
                                                              list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        for key in selector_keys:
            if key in cfg:
                cfg[key] = selector(cfg[key], note, key)
        return [(name, cfg)]

    return translate
