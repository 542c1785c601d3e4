"""Key translation of BlenderProc's renderers (RgbRenderer, SegMapRenderer and v1.0's single-pass renderers):
output keys, Cycles-only options, ``map_by``."""
from __future__ import annotations

from typing import Any, Callable

from ...errors import ConfigError
from .common import Note, pop_ignored
from .setup_keys import GLOBAL_IGNORED


_OUTPUT_KEYS = {"output_key": None, "segmap_output_key": None, "distance_output_key": "distance",
                "depth_output_key": "depth", "normals_output_key": "normals", "diffuse_color_output_key": "diffuse_color",
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
    pop_ignored(cfg, "output_file_prefix", note, "hybridgen names its own files")
    pop_ignored(cfg, "output_is_temp", note, GLOBAL_IGNORED["output_is_temp"])


def render_pixel_aspect(config: dict[str, Any], note: Note, version: Any) -> list[tuple[str, dict[str, Any]]]:
    """A renderer's ``pixel_aspect_x`` (taken out of ``config``): BlenderProc 1.0's renderers set Blender's pixel
    aspect when they render (their ``global.renderer`` default in its SUNCG and Replica examples: 4/3), so the
    camera renders from then on with ``fy = fx x pixel_aspect_x`` - a ``camera.PixelAspect`` entry to run before
    the renderer. BlenderProc 1.12's renderers do not read the key (a notice)."""
    if "pixel_aspect_x" not in config:
        return []
    value = config.pop("pixel_aspect_x")
    if version is not None:
        note("ignored: BlenderProc 1.12's renderers do not read it (a camera module's intrinsics do)",
             "pixel_aspect_x")
        return []
    return [("camera.PixelAspect", {"pixel_aspect_x": value})]


BLENDERPROC_LOBE_BOUNCES = {"glossy_bounces": 0, "transmission_bounces": 0}
"""BlenderProc's own defaults of its RgbRenderer (1.0 and 1.12; hybridgen's own default is ``max_bounces`` for
every lobe): no glossy or transmission bounce, so metals and mirrors reflect only the lights and glass renders
dark - what a BlenderProc config renders in BlenderProc."""


BLENDERPROC_VIEW = {"view_transform": "Filmic"}
"""BlenderProc 1.x never sets Blender's view transform, and Blender 2.93's scenes default to Filmic: its colors are
Filmic (hybridgen/render/view_transform.py; Blender 4.2's tables, whose 33^3 cube is the 65^3 one of 2.93
downsampled - not measured against 2.93 here)."""


def rgb(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    cfg = {**BLENDERPROC_LOBE_BOUNCES, **BLENDERPROC_VIEW, **config}
    _output_keys(cfg, note, "colors")
    _renderer_common(cfg, note)
    if "render_diffuse_color" in cfg:  # Blender's Diffuse Color pass: hybridgen's diffuse_color, not the base color
        cfg["render_diffuse_color"] = bool(cfg["render_diffuse_color"])
    if "render_normal" in cfg:
        cfg["render_normals"] = bool(cfg.pop("render_normal"))
    denoiser = cfg.pop("denoiser", None)
    if denoiser is not None:
        cfg["denoise"] = str(denoiser).upper() in ("INTEL", "OPTIX")
        if str(denoiser).upper() == "OPTIX":
            note("OptiX is Cycles' denoiser; hybridgen denoises with Open Image Denoise", "denoiser")
    pop_ignored(cfg, "transparent_background", note, "hybridgen color has no alpha; the background is the world color")
    for key in ("use_motion_blur", "motion_blur_length", "use_rolling_shutter", "rolling_shutter_length"):
        pop_ignored(cfg, key, note, "motion blur and rolling shutter are not simulated: each keypoint is a still frame")
    for key in ("cpu_threads", "simplify_subdivision_render", "light_sampling", "auto_tile_size", "tile_x",
                "tile_y"):
        pop_ignored(cfg, key, note, "a Cycles performance setting")
    return [("renderer.RgbRenderer", cfg)]


_LABEL_ONLY = {"render_depth": False, "render_distance": False, "render_normals": False, "map_by": None}


def segmap(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
    """BlenderProc's SegMapRenderer: one ``segmap`` dataset (``output_key``) with a channel per numeric map_by
    attribute, ``default_values`` for objects lacking one (:mod:`hybridgen.io.blenderproc_segmap`)."""
    cfg = dict(config)
    defaults = cfg.pop("default_values", None) or {}
    if not isinstance(defaults, dict):
        raise ConfigError("must map map_by attributes to values, e.g. {class: 0}", key="default_values")
    cfg["blenderproc_segmap"] = {"key": str(cfg.pop("output_key", "segmap")), "default_values": defaults}
    _output_keys(cfg, note, None)
    _renderer_common(cfg, note)
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


def single_pass(flag: str | None) -> Callable[[dict[str, Any], Note], list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        _output_keys(cfg, note, {"render_normals": "normals", "render_depth": "depth",
                                 "render_distance": "distance"}.get(flag or "", None))
        _renderer_common(cfg, note)
        for key in ("samples",):
            pop_ignored(cfg, key, note, "label passes are exact, sampled once at each pixel centre")
        out = {**_LABEL_ONLY, **cfg}
        if flag is not None:
            out[flag] = True
        else:  # FlowRenderer
            forward, backward = bool(out.pop("forward_flow", True)), bool(out.pop("backward_flow", False))
            out["render_flow"] = forward or backward
            pop_ignored(out, "blender_image_coordinate_style", note,
                 "hybridgen flow is in pixels, u right and v down (OpenCV image axes)")
        return [("renderer.SegMapRenderer", out)]

    return translate
