"""``bproc.renderer``: render settings, the label outputs to add, and ``render()`` (BlenderProc's RendererUtility).

Settings mean what they mean in BlenderProc (Cycles): ``set_max_amount_of_samples`` is the per-pixel maximum
and ``set_noise_threshold`` the adaptive-sampling threshold (0: every pixel gets the maximum), both as
hybridgen's :class:`~hybridgen.PathTraceSettings` reads Cycles' settings; ``set_light_bounces`` sets Cycles'
limits (max, diffuse, glossy, transmission; the AO, transparency and volume limits change nothing hybridgen
renders); ``set_denoiser`` ``INTEL`` (default) or ``OPTIX`` denoise with Open Image Denoise, None renders the
raw estimate. Settings that only change speed (threads, devices, light tree) are accepted;
``set_simplify_subdivision_render`` limits the levels of Subdivision Surface modifiers added after it (they are
applied when added: :mod:`hybridgen.bproc.types.modifiers`). ``render()`` itself is
:func:`hybridgen.bproc.render_frames.render_frames`; ``render_optical_flow`` and ``render_nocs`` are
:mod:`hybridgen.bproc.label_renders`.
"""
from __future__ import annotations

from typing import Any

from ..errors import InputError
from .render_frames import render_frames
from .session import SESSION
from .types.unsupported import fail, module_getattr

ANTIALIASING_DISTANCE_MAX = 10000.0
"""BlenderProc's default mist range (m): the background's value in an antialiased distance image."""
FILE_ENDINGS = {"PNG": ".png", "JPEG": ".jpg", "OPEN_EXR": ".exr"}
VIEW_TRANSFORMS = ("Standard", "Filmic", "AgX")
"""View transforms ``set_output_format`` takes: Standard is exact, the others render as Standard with a notice."""


def set_denoiser(denoiser: str | None) -> None:
    """``"INTEL"``, ``"OPTIX"`` (both: Open Image Denoise here) or None (no denoiser)."""
    if denoiser is not None and str(denoiser).upper() not in ("INTEL", "OPTIX"):
        raise InputError(f"No such denoiser: {denoiser} (INTEL, OPTIX or None)")
    SESSION.renderer.denoiser = None if denoiser is None else str(denoiser).upper()


def set_light_bounces(diffuse_bounces: int | None = None, glossy_bounces: int | None = None,
                      ao_bounces_render: int | None = None, max_bounces: int | None = None,
                      transmission_bounces: int | None = None, transparent_max_bounces: int | None = None,
                      volume_bounces: int | None = None) -> None:
    """Cycles' bounce limits (0: direct light only)."""
    settings = SESSION.renderer
    for name, value in (("diffuse_bounces", diffuse_bounces), ("glossy_bounces", glossy_bounces),
                        ("max_bounces", max_bounces), ("transmission_bounces", transmission_bounces)):
        if value is not None:
            if int(value) < 0:
                raise InputError(f"{name} must be >= 0, got {value}")
            setattr(settings, name, int(value))


def set_noise_threshold(noise_threshold: float) -> None:
    """Adaptive sampling's threshold (0: off, every pixel gets the maximum)."""
    if not float(noise_threshold) >= 0:
        raise InputError(f"noise_threshold must be >= 0, got {noise_threshold}")
    SESSION.renderer.noise_threshold = float(noise_threshold)


def set_max_amount_of_samples(samples: int) -> None:
    """The per-pixel maximum of samples."""
    if int(samples) < 1:
        raise InputError(f"samples must be >= 1, got {samples}")
    SESSION.renderer.samples = int(samples)


def set_output_format(file_format: str | None = None, color_depth: int | None = None,
                      enable_transparency: bool | None = None, jpg_quality: int | None = None,
                      view_transform: str | None = None) -> None:
    """What ``colors`` holds: ``file_format`` PNG (exact) or JPEG (the image after a JPEG round trip at
    ``jpg_quality``, as BlenderProc loads its ``.jpg`` back); ``color_depth`` 8 (uint8) or 16 (uint16, PNG only);
    ``view_transform`` Standard, Filmic (computed from Blender's own tables where a Blender or ``bpy`` is installed,
    else Standard with a notice) or AgX (Standard with a notice; :mod:`hybridgen.render.view_transform`).
    ``enable_transparency`` (Cycles' transparent film): a PNG's colors get an alpha channel, 0 (and RGB 0) where the camera sees the world, which
    still lights the scene (:mod:`hybridgen.bproc.frame_outputs`)."""
    settings = SESSION.renderer
    if enable_transparency is not None:
        settings.transparent = bool(enable_transparency)
    if view_transform is not None and view_transform not in VIEW_TRANSFORMS:
        fail(f"bproc.renderer.set_output_format(view_transform={view_transform!r})",
             f"views: {', '.join(VIEW_TRANSFORMS)}")
    fmt = settings.file_format if file_format is None else str(file_format).upper()
    if fmt not in ("PNG", "JPEG"):
        fail(f"bproc.renderer.set_output_format(file_format={file_format!r})", "PNG and JPEG are")
    depth = settings.color_depth if color_depth is None else int(color_depth)
    if depth not in (8, 16) or (fmt == "JPEG" and depth != 8):
        raise InputError(f"color_depth {color_depth} is not a {fmt} color depth (PNG: 8 or 16, JPEG: 8)")
    if jpg_quality is not None and not 0 <= int(jpg_quality) <= 100:
        raise InputError(f"jpg_quality must be in 0..100, got {jpg_quality}")
    settings.file_format, settings.color_depth = fmt, depth
    if jpg_quality is not None:
        settings.jpg_quality = int(jpg_quality)
    if view_transform is not None:
        settings.view_transform = view_transform


def map_file_format_to_file_ending(file_format: str) -> str:
    """``.png``, ``.jpg`` or ``.exr``."""
    if str(file_format).upper() not in FILE_ENDINGS:
        raise InputError(f"unknown file format: {file_format}")
    return FILE_ENDINGS[str(file_format).upper()]


def _enable(kind: str, options: dict[str, Any]) -> None:
    outputs = SESSION.renderer.outputs
    if kind in outputs:
        raise InputError(f"the {kind} output is already enabled; BlenderProc's enable_{kind}_output can not be "
                         "called twice")
    outputs[kind] = options


def enable_depth_output(activate_antialiasing: bool, output_dir: str | None = None, file_prefix: str = "depth_",
                        output_key: str = "depth", antialiasing_distance_max: float | None = None,
                        convert_to_distance: bool = False) -> None:
    """``depth``: float32 (H, W), z along the optical axis (m); the background is 1e10 (Cycles' Z pass) or, with
    ``activate_antialiasing``, the mist range converted to depth. hybridgen samples pixel centres (no
    antialiasing)."""
    if convert_to_distance:
        enable_distance_output(activate_antialiasing, output_dir, file_prefix, output_key, antialiasing_distance_max)
        return
    _enable("depth", {"output_key": output_key, "antialiasing": bool(activate_antialiasing),
                      "distance_max": antialiasing_distance_max or ANTIALIASING_DISTANCE_MAX})


def enable_distance_output(activate_antialiasing: bool, output_dir: str | None = None,
                           file_prefix: str = "distance_", output_key: str = "distance",
                           antialiasing_distance_max: float | None = None, convert_to_depth: bool = False) -> None:
    """``distance``: float32 (H, W), Euclidean distance from the camera centre (m); the background is
    ``antialiasing_distance_max`` (10000 m; with ``activate_antialiasing``) or the distance of Cycles' 1e10
    depth."""
    if convert_to_depth:
        enable_depth_output(activate_antialiasing, output_dir, file_prefix, output_key, antialiasing_distance_max)
        return
    _enable("distance", {"output_key": output_key, "antialiasing": bool(activate_antialiasing),
                         "distance_max": antialiasing_distance_max or ANTIALIASING_DISTANCE_MAX})


def enable_normals_output(output_dir: str | None = None, file_prefix: str = "normals_",
                          output_key: str = "normals") -> None:
    """``normals``: float32 (H, W, 3), camera frame in Blender axes (x right, y up, z backwards), encoded
    ``0.5 n + 0.5``; the background is 0.5 (a zero normal)."""
    _enable("normals", {"output_key": output_key})


def enable_segmentation_output(map_by: str | list[str] = "category_id", default_values: dict[str, Any] | None = None,
                               pass_alpha_threshold: float = 0.05, output_dir: str | None = None,
                               file_prefix: str = "segmap_", output_key: str = "segmap") -> None:
    """Segmentation by ``map_by`` (``instance``, ``class``/``category_id``, any custom property or attribute):
    ``<key>_segmaps`` images for numeric values, ``instance_attribute_maps`` for the rest
    (:mod:`hybridgen.bproc.segmentation`)."""
    _enable("segmentation", {"map_by": [map_by] if isinstance(map_by, str) else list(map_by),
                             "default_values": dict(default_values or {})})


def enable_diffuse_color_output(output_dir: str | None = None, file_prefix: str = "diffuse_",
                                output_key: str = "diffuse") -> None:
    """``diffuse``: uint8 (H, W, 3) sRGB of the surfaces' diffuse color (Blender's DiffCol pass as PNG)."""
    _enable("diffuse", {"output_key": output_key})


def render(output_dir: str | None = None, file_prefix: str = "rgb_", output_key: str | None = "colors",
           load_keys: set[str] | None = None, return_data: bool = True,
           keys_with_alpha_channel: set[str] | None = None, verbose: bool = False) -> dict[str, list[Any]]:
    """Render every frame of ``frame_start..frame_end``: ``{key: [one array per frame]}`` (see the module
    documentation of :mod:`hybridgen.bproc.render_frames`). The colors keep their alpha channel when the film is
    transparent (``set_output_format(enable_transparency=True)``, PNG) and ``output_key`` is in
    ``keys_with_alpha_channel`` (default then: ``{"colors"}``), as BlenderProc loads its RGBA files."""
    settings = SESSION.renderer
    if keys_with_alpha_channel is None:
        keys_with_alpha_channel = {"colors"} if settings.transparent else set()
    alpha = settings.transparent and settings.file_format == "PNG" and output_key in keys_with_alpha_channel
    return render_frames(output_key, load_keys, return_data, alpha)


def accept_speed_setting(*_args: Any, **_kwargs: Any) -> None:
    """A Cycles setting that changes speed or devices only: nothing to do."""


set_cpu_threads = set_render_devices = toggle_light_tree = enable_experimental_features = accept_speed_setting


def set_simplify_subdivision_render(simplify_subdivision_render: int) -> None:
    """Blender's Simplify limit on subdivision render levels (0: no limit; BlenderProc's init sets 3). hybridgen
    applies a Subdivision Surface modifier when it is added, so the limit holds for modifiers added later."""
    value = int(simplify_subdivision_render)
    if value < 0:
        raise InputError(f"bproc.renderer.set_simplify_subdivision_render: the limit must be at least 0, got {value}")
    SESSION.renderer.simplify_subdivision_render = value


def toggle_stereo(enable: bool) -> None:
    """Render left/right pairs (``bproc.camera.set_stereo_parameters``): every image of ``render()`` then has a
    leading axis of 2 (:mod:`hybridgen.bproc.render_frames`)."""
    SESSION.camera.stereo = bool(enable)


from .label_renders import render_nocs, render_optical_flow  # noqa: E402

from .segmap_render import render_segmap  # noqa: E402

__getattr__ = module_getattr("renderer", ["enable_motion_blur"])

from .world import set_world_background  # noqa: E402 - BlenderProc exports it from bproc.renderer
