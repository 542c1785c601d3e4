"""BlenderProc 1.x configs (v1.0 ``name:`` form and v1.12 ``module:`` form) read as hybridgen's.

:func:`translate_module` turns one BlenderProc module entry into hybridgen module entries: module names
BlenderProc used (``loader.ObjectLoader``, v1.0's ``renderer.NormalRenderer`` ...) become the hybridgen
module that does the same; keys are renamed and values converted (``add_properties``/``cp_*`` custom
properties become attributes, ``cf_set_*`` material functions become principled values, ``collision_shape:
CONVEX_HULL`` becomes ``convex_hull`` ...). What hybridgen does differently (Cycles-only options, Blender
modifiers) is reported through ``note`` as one line naming the key; nothing is dropped silently. Modules
that need Blender or a withdrawn dataset raise one ConfigError that says why and what to do instead.

This module holds no BlenderProc code or configs: it maps names and meanings, described from BlenderProc's
documentation, to hybridgen's own modules.
"""
from __future__ import annotations

import copy
from typing import Any, Callable

from ..errors import ConfigError

Note = Callable[[str, str], None]
"""``note(message, key)``: report one difference (a notice line, or an error in strict mode)."""

BLENDER_SETUP_KEYS = ("blender_install_path", "blender_version", "custom_blender_path", "blender_url",
                      "custom_blender_path_env")
"""``setup`` keys that locate or download Blender: hybridgen renders without Blender, so they are ignored."""

BLENDER_PYTHON_PACKAGES = frozenset({
    "h5py", "imageio", "pypng", "scikit-image", "scipy", "matplotlib", "pytz", "torch", "scikit-learn",
    "python-dateutil", "numpy", "pillow", "opencv-contrib-python", "opencv-python", "pyyaml", "smplx",
    "human_body_prior", "trimesh", "pyrender", "numba", "chumpy", "tqdm",
})
"""Packages BlenderProc configs install into Blender's own Python; hybridgen's modules do not import them
through the config, so a missing one is a notice, not an error."""

GLOBAL_IGNORED = {
    "sys_paths": "Blender's Python import paths; hybridgen needs none",
    "transparency_bounces": "Cycles' limit on alpha-transparent surfaces; hybridgen's materials are opaque or "
                            "refractive (transmission_bounces)",
    "volume_bounces": "hybridgen renders no volumes",
    "output_is_temp": "hybridgen keeps no temporary per-frame files; writers write the final files",
    "pixel_aspect_x": "hybridgen cameras have square pixels unless cam_K says otherwise",
    "pixel_aspect_y": "hybridgen cameras have square pixels unless cam_K says otherwise",
    "data_set_name": "a dataset loader setting (Replica); that loader is not available",
    "data_path": "a dataset loader setting; that loader is not available",
    "avoid_rendering": "hybridgen always renders what the config's renderers ask",
}
"""``global`` keys that only configure Blender or BlenderProc internals: ignored with a notice."""

ALIASES = {
    "loader.ObjectLoader": "loader.ObjLoader",
    "loader.PlyLoader": "loader.ObjLoader",
    "renderer.NormalRenderer": "renderer.SegMapRenderer",
    "renderer.DepthRenderer": "renderer.SegMapRenderer",
    "renderer.DistanceRenderer": "renderer.SegMapRenderer",
    "renderer.FlowRenderer": "renderer.SegMapRenderer",
    "object.PositionSampler": "object.ObjectPoseSampler",
    "manipulators.ObjectManipulator": "manipulators.EntityManipulator",
    "manipulators.LightManipulator": "manipulators.EntityManipulator",
    "manipulators.FloorExtractor": "object.FloorExtractor",
    "object.ObjectReplacer": "object.ObjectSwapper",
    "constructor.BasicMeshInitializer": "loader.PrimitiveLoader",
}
"""BlenderProc module name -> the hybridgen module that does its work (keys translated below)."""

_EXPORT = "export the scene to glTF/GLB or OBJ (e.g. with Blender: File > Export) and load it with loader.ObjLoader"
_DATASET = "convert its meshes to OBJ/glTF/PLY and load them with loader.ObjLoader"
UNAVAILABLE = {
    "loader.BlendLoader": f"reading .blend files needs Blender; {_EXPORT}",
    "loader.SuncgLoader": f"the SUNCG dataset was withdrawn by its authors and is not distributed; {_DATASET}",
    "lighting.SuncgLighting": "lights SUNCG scenes, a dataset that was withdrawn; use lighting.SurfaceLighting "
                              "with a selector for the lamp objects",
    "camera.SuncgCameraSampler": "samples cameras inside SUNCG rooms (a withdrawn dataset); use "
                                 "camera.CameraSampler with proximity_checks",
    "loader.ShapeNetLoader": f"ShapeNet's catalogue layout is not read by hybridgen; {_DATASET}",
    "writer.ShapeNetWriter": "writes ShapeNet ids of the loader hybridgen does not have; use attributes + map_by",
    "loader.SceneNetLoader": f"SceneNet's layout is not read by hybridgen; {_DATASET}",
    "loader.Front3DLoader": f"3D-FRONT's JSON scenes are not read by hybridgen; {_DATASET}",
    "camera.Front3DCameraSampler": "samples inside 3D-FRONT rooms; use camera.CameraSampler with "
                                   "proximity_checks",
    "loader.Pix3DLoader": f"Pix3D's layout is not read by hybridgen; {_DATASET}",
    "loader.IKEALoader": f"the IKEA dataset's layout is not read by hybridgen; {_DATASET}",
    "loader.ReplicaLoader": f"Replica's layout is not read by hybridgen; its mesh.ply loads with loader.ObjLoader",
    "camera.ReplicaCameraSampler": "samples inside Replica scenes; use camera.CameraSampler with proximity_checks",
    "loader.AMASSLoader": "posing SMPL bodies needs the AMASS data and the SMPL body model (licensed, not "
                          "distributable); export posed bodies to OBJ and load them with loader.ObjLoader",
    "loader.RockEssentialsRockLoader": "reads Blender .blend rock packs; " + _EXPORT,
    "constructor.RockEssentialsGroundConstructor": "builds Blender node-displaced ground; use "
                                                   "loader.PrimitiveLoader (plane) with a texture",
    "materials.RockEssentialsTextureSampler": "samples Blender node textures; use manipulators.MaterialManipulator",
    "constructor.RandomRoomConstructor": "extrudes rooms from Blender meshes with loaders hybridgen does not have; "
                                         "model the room and load it with loader.ObjLoader",
    "constructor.BasicEmptyInitializer": "Blender empties (axes without geometry) have no counterpart in "
                                         "hybridgen scenes; use a location directly where an empty was a target",
    "object.CalibrationboardSampler": "samples a Blender calibration-board asset; load the board as a mesh "
                                      "and place it with object.ObjectPoseSampler",
    "writer.StereoGlobalMatchingWriter": "stereo depth by SGM is not implemented; renderer.RgbRenderer with "
                                         "stereo: true writes exact per-eye depth instead",
    "composite.CameraObjectSampler": "not implemented yet: it re-samples objects and cameras together per "
                                     "scene; use main.Initializer number_of_scenes with object.ObjectPoseSampler "
                                     "and camera.CameraSampler (each scene draws both anew)",
    "writer.MyWriter": "an example of a user plugin; write it as a hybridgen plugin (entry point "
                       "'hybridgen.modules')",
}
"""Modules hybridgen cannot provide: one line why, and what to do instead."""


def _pop(config: dict[str, Any], key: str, note: Note, why: str) -> Any:
    """Remove ``key`` and report it as ignored (when present)."""
    if key not in config:
        return None
    value = config.pop(key)
    note(f"ignored: {why}", key)
    return value


def _number(value: Any) -> Any:
    """BlenderProc stores custom properties given as strings ("1"): numeric strings become numbers."""
    if isinstance(value, str):
        try:
            return int(value)
        except ValueError:
            try:
                return float(value)
            except ValueError:
                return value
    return value


def custom_properties(values: dict[str, Any], config: dict[str, Any]) -> None:
    """``cp_<name>: value`` -> attribute ``<name>`` (``cp_category_id`` -> ``category_id``) into ``config``."""
    for key, value in values.items():
        name = key[3:] if key.startswith("cp_") else key
        if name == "category_id":
            config["category_id"] = _number(value)
        else:
            config.setdefault("attributes", {})[name] = _number(value)


def selector(value: Any, note: Note, key: str = "selector") -> Any:
    """A BlenderProc ``getter.Entity`` selector in hybridgen's terms: ``type: MESH`` always holds."""
    if isinstance(value, dict):
        out = dict(value)
        if not any(k in out for k in ("provider", "conditions", "random_samples", "index", "check_empty")):
            out = {"conditions": out}
        out.setdefault("check_empty", False)  # BlenderProc: an empty selection does nothing
        if "conditions" in out:
            out["conditions"] = _conditions(out["conditions"], note, f"{key}.conditions")
        provider = out.get("provider")
        if provider not in (None, "getter.Entity"):
            raise ConfigError(f"provider {provider!r} selects something other than objects; hybridgen "
                              "modules select objects with getter.Entity", key=f"{key}.provider")
        return out
    return value


def _conditions(conditions: Any, note: Note, key: str) -> Any:
    if isinstance(conditions, list):
        return [_conditions(c, note, f"{key}[{i}]") for i, c in enumerate(conditions)]
    if not isinstance(conditions, dict):
        return conditions
    out = {}
    for name, wanted in conditions.items():
        if name == "type":
            if str(wanted).upper() != "MESH":
                raise ConfigError(f"hybridgen scenes select mesh objects only, got type {wanted!r}",
                                  key=f"{key}.type")
            continue  # every hybridgen object is a mesh
        out[name] = _number(wanted) if name.startswith("cp_") or name == "category_id" else wanted
    return out


_UNIFORM = ("sampler.Uniform3d", "Uniform3dSampler", "sampler.Value", "ValueSampler", "sampler.Color",
            "ColorSampler")


def samplers_as_blenderproc(value: Any, note: Note, key: str) -> Any:
    """Sampler specs drawn as BlenderProc draws them: ``min`` above ``max`` (numpy draws between the two, so
    BlenderProc's examples use it) becomes the same range ordered; PartSphere's ``part_sphere_vector`` is
    hybridgen's ``part_sphere_dir_vector``."""
    if isinstance(value, list):
        return [samplers_as_blenderproc(v, note, f"{key}[{i}]") for i, v in enumerate(value)]
    if not isinstance(value, dict):
        return value
    out = {k: samplers_as_blenderproc(v, note, f"{key}.{k}") for k, v in value.items()}
    provider = out.get("provider", out.get("name"))
    if provider == "getter.Entity":  # a selector anywhere (getter.POI's, samplers' ...): type MESH always holds
        out["conditions"] = _conditions(out.get("conditions"), note, f"{key}.conditions")
        if out["conditions"] is None:
            del out["conditions"]
    params = out.get("parameters", out)
    if provider in _UNIFORM and isinstance(params, dict) and "min" in params and "max" in params:
        low, high = params["min"], params["max"]
        if isinstance(low, list) and isinstance(high, list) and len(low) == len(high) and \
                all(isinstance(v, (int, float)) for v in low + high) and any(a > b for a, b in zip(low, high)):
            params["min"], params["max"] = [min(a, b) for a, b in zip(low, high)], \
                [max(a, b) for a, b in zip(low, high)]
        elif isinstance(low, (int, float)) and isinstance(high, (int, float)) and low > high:
            params["min"], params["max"] = high, low
    if provider in ("sampler.UpperRegionSampler", "UpperRegionSampler") and isinstance(params, dict) and \
            "use_ray_trace_check" in params:
        if params.pop("use_ray_trace_check"):
            note("the ray check that nothing blocks the sampled point from the surface is not done; the "
                 "placing module's collision check still applies", f"{key}.use_ray_trace_check")
    if provider in ("sampler.PartSphere", "PartSphereSampler") and isinstance(params, dict) and \
            "part_sphere_vector" in params:
        params["part_sphere_dir_vector"] = params.pop("part_sphere_vector")
    return out


def _matrix_world(cfg: dict[str, Any]) -> None:
    """``matrix_world`` (4x4, metres) -> location, Euler XYZ rotation and scale."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    if "matrix_world" not in cfg:
        return
    try:
        matrix = np.asarray(cfg.pop("matrix_world"), dtype=np.float64).reshape(4, 4)
    except (TypeError, ValueError):
        raise ConfigError("must be a 4x4 matrix", key="matrix_world") from None
    linear = matrix[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale == 0) or not np.all(np.isfinite(matrix)):
        raise ConfigError("must be an invertible, finite 4x4 matrix", key="matrix_world")
    rotation = linear / scale
    if np.linalg.det(rotation) < 0:
        scale[0], rotation[:, 0] = -scale[0], -rotation[:, 0]
    if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-4):
        raise ConfigError("must be a rotation times a per-axis scale (no shear)", key="matrix_world")
    cfg.setdefault("location", matrix[:3, 3].tolist())
    cfg.setdefault("rotation", Rotation.from_matrix(rotation).as_euler("xyz").tolist())
    if "scale" in cfg:  # BlenderProc sets matrix_world, then scale on top of it
        given = np.broadcast_to(np.asarray(cfg["scale"], dtype=np.float64), (3,))
        cfg["scale"] = (scale * given).tolist()
    else:
        cfg["scale"] = scale.tolist()


_BLENDER_PRIMITIVES = {"plane": ("plane", "Plane"), "cube": ("cube", "Cube"), "uvsphere": ("sphere", "Sphere"),
                       "icosphere": ("sphere", "Icosphere"), "cylinder": ("cylinder", "Cylinder"),
                       "cone": ("cone", "Cone"), "torus": ("torus", "Torus")}


def _mesh_initializer(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
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


def _bop_loader(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    _shading(cfg, note)
    return [("loader.BopLoader", cfg)]


def _replacer(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
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


def _loader(name: str, config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
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
        _pop(cfg, key, note, why)
    _shading(cfg, note)
    entries = [dict(cfg, path=p) for p in paths] if isinstance(paths, list) else [cfg]
    return [("loader.ObjLoader", e) for e in entries]


def _shading(cfg: dict[str, Any], note: Note) -> None:
    _pop(cfg, "cf_set_shading", note, "Blender's smooth/flat shading switch; hybridgen shades with the mesh's "
         "own normals (vertex normals smooth, none flat)")
    _pop(cfg, "cf_shading_auto_smooth_angle_in_deg", note, "Blender's auto-smooth angle")


_OUTPUT_KEYS = {"output_key": None, "segmap_output_key": None, "distance_output_key": "distance",
                "depth_output_key": "depth", "normals_output_key": "normals", "diffuse_color_output_key": "albedo",
                "segcolormap_output_key": "instance_attribute_maps",
                "forward_flow_output_key": "forward_flow", "backward_flow_output_key": "backward_flow"}


def _output_keys(cfg: dict[str, Any], note: Note, default: str | None) -> None:
    """BlenderProc's ``output_key`` (the renderer's main pass, ``default``) and ``*_output_key`` become
    hybridgen's ``output_keys`` {pass: stored name}: the dataset is stored under BlenderProc's name."""
    names = dict(cfg.get("output_keys") or {})
    for key, own in _OUTPUT_KEYS.items():
        if key not in cfg:
            continue
        value = cfg.pop(key)
        name = default if key == "output_key" else own
        if name is None:
            note(f"BlenderProc's '{value}' has no single hybridgen dataset (segmentation is stored per "
                 "attribute as '<attr>_segmaps'); those keep hybridgen's names", key)
        elif value != name:
            names[name] = str(value)
    if names:
        cfg["output_keys"] = names


def _renderer_common(cfg: dict[str, Any], note: Note) -> None:
    _pop(cfg, "use_alpha", note, "hybridgen images carry no alpha channel")
    _pop(cfg, "image_type", note, "image file formats are the writers' choice (color_file_format)")
    _pop(cfg, "output_file_prefix", note, "hybridgen names its own files")
    _pop(cfg, "output_is_temp", note, GLOBAL_IGNORED["output_is_temp"])


def _rgb(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    _output_keys(cfg, note, "colors")
    _renderer_common(cfg, note)
    if "render_diffuse_color" in cfg:
        cfg["render_albedo"] = bool(cfg.pop("render_diffuse_color"))
    if "render_normal" in cfg:
        cfg["render_normals"] = bool(cfg.pop("render_normal"))
    denoiser = cfg.pop("denoiser", None)
    if denoiser is not None:
        cfg["denoise"] = str(denoiser).upper() in ("INTEL", "OPTIX")
        if str(denoiser).upper() == "OPTIX":
            note("OptiX is Cycles' denoiser; hybridgen denoises with Open Image Denoise", "denoiser")
    _pop(cfg, "transparent_background", note, "hybridgen color has no alpha; the background is the world color")
    for key in ("use_motion_blur", "motion_blur_length", "use_rolling_shutter", "rolling_shutter_length"):
        _pop(cfg, key, note, "motion blur and rolling shutter are not simulated: each keypoint is a still frame")
    for key in ("cpu_threads", "simplify_subdivision_render", "light_sampling", "auto_tile_size", "tile_x",
                "tile_y"):
        _pop(cfg, key, note, "a Cycles performance setting")
    return [("renderer.RgbRenderer", cfg)]


_LABEL_ONLY = {"render_depth": False, "render_distance": False, "render_normals": False, "map_by": None}


def _segmap(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    _output_keys(cfg, note, None)
    _renderer_common(cfg, note)
    defaults = cfg.pop("default_values", None)
    if defaults:
        note("objects lacking a map_by attribute get 0 (background) in hybridgen unless main.Initializer's "
             "default_category_id is set", "default_values")
    cfg["map_by"] = _map_by(cfg.get("map_by", "class"), note)  # "class": BlenderProc's default
    # BlenderProc's SegMapRenderer writes only segmentation; hybridgen's would add depth and normals
    cfg.setdefault("render_depth", False)
    cfg.setdefault("render_normals", False)
    return [("renderer.SegMapRenderer", cfg)]


def _map_by(value: Any, note: Note) -> Any:
    """BlenderProc's map_by: ``name`` (text) lives in instance_attribute_maps, as BlenderProc's segcolormap
    holds it; ``cp_<attr>`` is hybridgen's attribute ``<attr>``."""
    items = [value] if isinstance(value, str) else list(value) if isinstance(value, list) else value
    if not isinstance(items, list):
        return value
    out: list[str] = []
    for item in items:
        if item == "name":
            item = "instance"  # instance_attribute_maps carry each instance's name
        elif isinstance(item, str) and item.startswith("cp_"):
            item = item[3:]
        if item not in out:
            out.append(item)
    return out


def _single_pass(flag: str | None) -> Callable[[dict[str, Any], Note], list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        _output_keys(cfg, note, {"render_normals": "normals", "render_depth": "depth",
                                 "render_distance": "distance"}.get(flag or "", None))
        _renderer_common(cfg, note)
        for key in ("samples",):
            _pop(cfg, key, note, "label passes are exact, sampled once at each pixel centre")
        out = {**_LABEL_ONLY, **cfg}
        if flag is not None:
            out[flag] = True
        else:  # FlowRenderer
            forward, backward = bool(out.pop("forward_flow", True)), bool(out.pop("backward_flow", False))
            out["render_flow"] = forward or backward
            _pop(out, "blender_image_coordinate_style", note,
                 "hybridgen flow is in pixels, u right and v down (OpenCV image axes)")
        return [("renderer.SegMapRenderer", out)]

    return translate


def _postprocessing(cfg: dict[str, Any], note: Note, state: dict[str, Any]) -> None:
    modules = cfg.pop("postprocessing_modules", None)
    if not modules:
        return
    if not isinstance(modules, dict):
        raise ConfigError("must map an output key to a list of {module: postprocessing.X}",
                          key="postprocessing_modules")
    for output, steps in modules.items():
        for step in steps or []:
            name = step.get("module") or step.get("name") if isinstance(step, dict) else step
            if name == "postprocessing.Dist2Depth":
                state["dist2depth"] = True  # depth is rendered exactly instead of converted from distance
            elif name == "postprocessing.TrimRedundantChannels":
                pass  # hybridgen's depth/distance are single-channel already
            elif name == "postprocessing.OilPaintFilter":
                note("the oil-paint filter is not implemented", f"postprocessing_modules.{output}")
            else:
                raise ConfigError(f"unknown postprocessing module {name!r}; hybridgen knows "
                                  "postprocessing.Dist2Depth and postprocessing.TrimRedundantChannels",
                                  key=f"postprocessing_modules.{output}")


def _writer(kind: str) -> Callable[[dict[str, Any], Note, dict[str, Any]], list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note, state: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        _postprocessing(cfg, note, state)
        _pop(cfg, "write_alpha_channel", note, "hybridgen images carry no alpha channel")
        _pop(cfg, "output_file_prefix", note, "hybridgen names its own files")
        if kind == "writer.BopWriter":
            if "m2mm" in cfg:
                cfg["annotation_unit"] = "mm" if cfg.pop("m2mm") else "m"
            if state.get("blenderproc") and "output_dir" not in cfg:
                state.setdefault("subdirs", {})[id(cfg)] = "bop_data"
        if kind == "writer.CocoAnnotationsWriter" and state.get("blenderproc"):
            if "output_dir" not in cfg:
                state.setdefault("subdirs", {})[id(cfg)] = "coco_data"
            cfg.setdefault("image_names", "blenderproc")  # rgb_%04d.png next to the JSON, as BlenderProc
            if cfg.pop("segmap_output_key", "segmap") != "segmap":
                note("hybridgen's COCO writer reads the renderer's instance_segmaps (segmentation is stored per "
                     "attribute, not as one BlenderProc segmap)", "segmap_output_key")
        return [(kind, cfg)]

    return translate


def _entity(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    if "selector" in cfg:
        cfg["selector"] = selector(cfg["selector"], note)
    props = {k: cfg.pop(k) for k in list(cfg) if k.startswith("cp_")}
    custom_properties(props, cfg)
    if "rotation_euler" in cfg:
        cfg["rotation"] = cfg.pop("rotation_euler")
    _matrix_world(cfg)
    mode = cfg.get("mode")
    if "cf_randomize_materials" in cfg:
        cfg.pop("mode", None)  # the randomizer draws once for all or for each, as BlenderProc
    _mode(cfg, note)
    _shading(cfg, note)
    for key in ("cf_add_modifier", "cf_add_displace_modifier_with_texture", "cf_add_uv_mapping"):
        _pop(cfg, key, note, "Blender modifiers (displacement, subdivision, UV projection) are not applied")
    out = []
    randomize = cfg.pop("cf_randomize_materials", None)
    if randomize is not None:
        if not isinstance(randomize, dict):
            raise ConfigError("must be a mapping {randomization_level, materials_to_replace_with}",
                              key="cf_randomize_materials")
        extra = [k for k in randomize if k not in ("randomization_level", "materials_to_replace_with")]
        if extra:
            raise ConfigError(f"unknown key {extra[0]!r}; hybridgen takes randomization_level and "
                              "materials_to_replace_with", key="cf_randomize_materials")
        source = randomize.get("materials_to_replace_with")
        if isinstance(source, dict):
            source = {k: v for k, v in source.items() if k != "check_empty"}
        out.append(("manipulators.MaterialRandomizer", {
            "selector": cfg.get("selector", {"conditions": {}}),
            "randomization_level": randomize.get("randomization_level", 0.2),
            "materials_to_replace_with": source, "mode": mode or "once_for_each"}))
    if set(cfg) - {"selector"} or not out:
        out.insert(0, ("manipulators.EntityManipulator", cfg))
    return out


def _mode(cfg: dict[str, Any], note: Note) -> None:
    mode = cfg.pop("mode", None)
    if mode not in (None, "once_for_each"):
        note(f"mode {mode!r}: hybridgen draws sampled values once for each selected object", "mode")


_MATERIAL_VALUES = {"base_color": "base_color", "roughness": "roughness", "metallic": "metallic",
                    "specular": "specular", "ior": "ior", "alpha": "alpha", "transmission": "transmission",
                    "emission_strength": "emission_strength", "emission": "emission"}


def _material(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    sel = cfg.get("selector")
    if isinstance(sel, dict) and sel.get("provider") == "getter.Material":
        # materials are selected through the objects that carry them (hybridgen objects hold one material)
        conditions = sel.get("conditions", {})
        cfg["selector"] = {k: v for k, v in sel.items() if k not in ("provider", "conditions")}
        cfg["selector"]["conditions"] = _material_conditions(conditions)
        cfg["selector"].setdefault("check_empty", False)
    elif "selector" in cfg:
        cfg["selector"] = selector(cfg["selector"], note)
    _mode(cfg, note)
    values = dict(cfg.pop("material", {}) or {})
    for key in list(cfg):
        if not key.startswith("cf_"):
            continue
        function = key[3:]
        if function.startswith("set_"):
            name = function[4:].lower().replace(" ", "_")
            if name in _MATERIAL_VALUES:
                values[_MATERIAL_VALUES[name]] = cfg.pop(key)
                continue
        if function == "switch_to_emission_shader":
            emission = cfg.pop(key) or {}
            color = emission.get("color", [1.0, 1.0, 1.0, 1.0]) if isinstance(emission, dict) else [1, 1, 1, 1]
            values["emission"] = color[:3] if isinstance(color, list) else color
            values["emission_strength"] = emission.get("strength", 1.0) if isinstance(emission, dict) else 1.0
            continue
        _pop(cfg, key, note, f"Blender node-graph function '{function}' has no counterpart in hybridgen's "
             "principled material")
    cfg["material"] = values
    return [("manipulators.MaterialManipulator", cfg)]


def _material_conditions(conditions: Any) -> Any:
    if isinstance(conditions, list):
        return [_material_conditions(c) for c in conditions]
    if not isinstance(conditions, dict):
        return conditions
    return {("material_name" if k == "name" else k): v for k, v in conditions.items()}


_SHAPES = {"CONVEX_HULL": "convex_hull", "MESH": "mesh", "CONVEX_DECOMPOSITION": "convex_decomposition",
           "BOX": "box", "SPHERE": "sphere"}


def _physics(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
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
        _pop(cfg, key, note, "hybridgen derives mass from the collision volume x density (key 'density')")
    _pop(cfg, "steps_per_sec", note, "hybridgen steps at time_step")
    return [("object.PhysicsPositioning", cfg)]


def _camera_loader(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    defaults = cfg.get("default_cam_param")
    if isinstance(defaults, dict):  # v1.0 puts intrinsics (fov, resolution) among the pose defaults
        intrinsic_keys = ("fov", "resolution_x", "resolution_y", "cam_K", "clip_start", "clip_end")
        moved = {k: defaults[k] for k in intrinsic_keys if k in defaults}
        if moved:
            cfg["default_cam_param"] = {k: v for k, v in defaults.items() if k not in moved}
            cfg["intrinsics"] = {**moved, **(cfg.get("intrinsics") or {})}
    return [("camera.CameraLoader", cfg)]


def _pose_sampler(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = dict(config)
    if "objects_to_sample" in cfg:
        cfg["objects_to_sample"] = selector(cfg["objects_to_sample"], note, "objects_to_sample")
    else:  # v1.0 PositionSampler / BlenderProc default: every object with physics... every mesh
        cfg["objects_to_sample"] = {"conditions": {}}
    return [("object.ObjectPoseSampler", cfg)]


def _passthrough(name: str, *selector_keys: str) -> Callable[[dict[str, Any], Note],
                                                              list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        for key in selector_keys:
            if key in cfg:
                cfg[key] = selector(cfg[key], note, key)
        return [(name, cfg)]

    return translate


TRANSLATORS: dict[str, Callable[..., list[tuple[str, dict[str, Any]]]]] = {
    "loader.ObjectLoader": lambda c, n: _loader("loader.ObjectLoader", c, n),
    "loader.ObjLoader": lambda c, n: _loader("loader.ObjLoader", c, n),
    "loader.PlyLoader": lambda c, n: _loader("loader.PlyLoader", c, n),
    "renderer.RgbRenderer": _rgb,
    "renderer.SegMapRenderer": _segmap,
    "renderer.NormalRenderer": _single_pass("render_normals"),
    "renderer.DepthRenderer": _single_pass("render_depth"),
    "renderer.DistanceRenderer": _single_pass("render_distance"),
    "renderer.FlowRenderer": _single_pass(None),
    "manipulators.EntityManipulator": _entity,
    "manipulators.ObjectManipulator": _entity,
    "manipulators.MaterialManipulator": _material,
    "object.PhysicsPositioning": _physics,
    "camera.CameraLoader": _camera_loader,
    "object.ObjectPoseSampler": _pose_sampler,
    "object.PositionSampler": _pose_sampler,
    "object.OnSurfaceSampler": _passthrough("object.OnSurfaceSampler", "objects_to_sample", "surface"),
    "lighting.SurfaceLighting": _passthrough("lighting.SurfaceLighting", "selector"),
    "constructor.BasicMeshInitializer": _mesh_initializer,
    "loader.BopLoader": _bop_loader,
    "object.ObjectReplacer": _replacer,
    "object.FloorExtractor": _passthrough("object.FloorExtractor", "selector"),
    "object.Hide": _passthrough("object.Hide", "selector"),
    "manipulators.FloorExtractor": _passthrough("object.FloorExtractor", "selector"),
}
KEYS_ONLY_BLENDERPROC = ("constructor.BasicMeshInitializer", "object.ObjectReplacer", "renderer.NormalRenderer",
                         "renderer.DepthRenderer", "renderer.DistanceRenderer", "renderer.FlowRenderer",
                         "loader.ObjectLoader", "loader.PlyLoader")
"""BlenderProc names whose keys are BlenderProc's in any config (hybridgen has no module of that name)."""
WRITERS = {name: _writer(name) for name in ("writer.Hdf5Writer", "writer.BopWriter", "writer.CocoAnnotationsWriter")}


def translate_module(name: str, config: dict[str, Any], note: Note,
                     state: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    """hybridgen ``(module name, config)`` entries doing what BlenderProc's ``name`` with ``config`` does.

    Keys and defaults are translated for configs in BlenderProc's form (``state["blenderproc"]``: a
    ``version``, ``module:`` entries or Blender ``setup`` keys); hybridgen's own form only resolves names.
    ``state`` carries what one module tells others (``postprocessing.Dist2Depth`` asks the renderers for
    depth); :func:`finish` applies it once every module is translated.
    """
    if name in UNAVAILABLE:
        raise ConfigError(f"not available in hybridgen: {UNAVAILABLE[name]}", key="module")
    if not state.get("blenderproc") and name not in KEYS_ONLY_BLENDERPROC:
        return [(ALIASES.get(name, name), config)]  # hybridgen's own form: names only, hybridgen's keys
    config = samplers_as_blenderproc(copy.deepcopy(config), note, "config")
    if name in WRITERS:
        return WRITERS[name](config, note, state)
    if name in TRANSLATORS:
        return TRANSLATORS[name](config, note)
    return [(ALIASES.get(name, name), config)]


def _as_list(value: Any) -> list[Any]:
    return [] if value is None else [value] if isinstance(value, str) else list(value)


def _coco_reads_renamed(coco: dict[str, Any], renderers: list[dict[str, Any]]) -> None:
    """A COCO writer whose keys are not given (or BlenderProc's defaults) reads the passes under the names the
    renderers before it store them (their ``output_keys``)."""
    stored = {own: name for r in renderers for own, name in (r.get("output_keys") or {}).items()}
    for key, own, blenderproc_default in (("rgb_output_key", "colors", "colors"),
                                          ("segcolormap_output_key", "instance_attribute_maps", "segcolormap")):
        if coco.get(key, blenderproc_default) == blenderproc_default:
            coco[key] = stored.get(own, own)


def finish(entries: list[Any], state: dict[str, Any], output_dir: Any) -> None:
    """Cross-module effects: Dist2Depth renders depth where distance was rendered; writers' BlenderProc folders."""
    if not state.get("blenderproc"):
        return
    if state.get("dist2depth"):
        for entry in entries:
            if entry.name.startswith("renderer.") and entry.config.get("render_distance"):
                entry.config["render_distance"] = False
                entry.config["render_depth"] = True
    for position, entry in enumerate(entries):
        if entry.name not in ("writer.BopWriter", "writer.CocoAnnotationsWriter"):
            continue
        # BlenderProc's BOP writer renders its own masks and depth; hybridgen's writers take them from the
        # renderer before them, which is asked for them here
        renderers = [e for e in entries[:position] if e.name.startswith("renderer.")]
        if not renderers:
            continue
        last = renderers[-1].config
        if entry.name == "writer.CocoAnnotationsWriter":
            _coco_reads_renamed(entry.config, [e.config for e in renderers])
        else:  # BlenderProc's BOP writer renders its own: hybridgen's reads the passes under their stored names
            stored = {own: name for e in renderers for own, name in (e.config.get("output_keys") or {}).items()
                      if own in ("colors", "depth", "instance_segmaps")}
            if stored and entry.config.get("input_keys") is None:
                entry.config["input_keys"] = stored
        if not any("instance" in _as_list(e.config.get("map_by")) for e in renderers):
            last["map_by"] = [*_as_list(last.get("map_by")), "instance"]
        if entry.name == "writer.BopWriter" and not any(e.config.get("render_depth") for e in renderers):
            last["render_depth"] = True
    subdirs = state.get("subdirs", {})
    if subdirs and isinstance(output_dir, str):
        for entry in entries:
            sub = subdirs.get(id(entry.config))
            if sub is not None:
                entry.config["output_dir"] = f"{output_dir.rstrip('/')}/{sub}"
