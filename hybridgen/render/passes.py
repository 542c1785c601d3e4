"""The pass catalogue: every output key a renderer can write, declared once (docs/conventions.md section 3).

An entry says what the key holds (dtype, per-keypoint shape, units, axes, background), how it is made from
one keypoint's readback (``compute(frame, key)`` on a :class:`~hybridgen.render.raster.keypoint_frame.KeypointFrame`,
and which readbacks that needs), how it is asked for (``option``: the renderer parameter, which the renderer
modules declare from here; :func:`hint`: the line writers print), how each output format stores it (``hdf5``: the compact encoding of ``data.hdf5``; ``blenderproc``:
BlenderProc's per-keypoint files; ``png``/``exr_channels``: ``hybridgen extract``) and how ``vis`` shows it
(``show``). Adding a pass = one entry here + its test. The renderer options select keys
(:class:`~hybridgen.render.raster.label_request.LabelRequest`); readers recognise stored keys with :func:`recognise`
(exact name first, then the glob ``pattern`` of renamed or family keys, e.g. ``<attribute>_segmaps``).

How a writer (frame sink) asks for a pass and reads it
------------------------------------------------------
Passes with ``on_request`` (``amodal_masks``, ``visible_fractions``, ``object_boxes``) are never stored by
other writers and made only when a sink asks: give the sink a method ``wanted_passes() -> Collection[str]``
returning their keys. Every renderer that also makes the pass's ``with_keys`` (here ``instance_segmaps``)
then computes them, announces them in ``begin`` (``PassLayout`` dtype ``"object"``) and hands them to
``write(index, values)`` of the sinks that asked only, in the same ``values`` as ``instance_segmaps``:
``values["amodal_masks"][instance_id]`` is the object's (H, W) bool full silhouette inside the image, and so
on (see :mod:`hybridgen.render.raster.object_passes`). A sink that reads only some objects says which with
``wanted_objects() -> Collection[int] | None`` (instance ids, asked after its ``begin``; None: all): only those
are drawn alone. In the Python API, ``MemorySink(wanted=[...])`` asks for them.
:func:`hint` gives the line to print when a key is missing.
"""
from __future__ import annotations

import fnmatch
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..io.frame_sink import PassLayout
from .raster import raster_passes as raster
from .raster.geometry_passes import nocs, object_coordinates, optical_flow
from .raster.object_passes import amodal_masks, object_boxes, visible_fractions
from .raster.object_records import object_records

if TYPE_CHECKING:
    from .raster.keypoint_frame import KeypointFrame

Compute = Callable[["KeypointFrame", str], Any]
INSTANCE_HINT = "add 'instance' to map_by of the renderer (renderer.SegMapRenderer or renderer.RgbRenderer)"


@dataclass(frozen=True)
class PassSpec:
    """One output key (see the module documentation for what each field is for).

    ``dtype``: numpy dtype name, ``"json"`` (a JSON-ready value) or ``"object"`` (a Python value handed to
    the sinks that asked, never stored). ``channels``: 0 for (H, W), k for (H, W, k), None for one value
    per keypoint. ``needs``: readbacks - ``raster`` (the label draw), ``silhouettes`` (objects drawn alone),
    ``neighbours`` (the depth of keypoints i - 1, i + 1), ``albedo`` (the albedo draw), ``path_trace``
    (made by the color producer; ``compute`` is None). ``png``: ``millimetres`` (16-bit, value *
    depth_scale = mm), ``srgb`` (linear -> 8-bit sRGB), ``half_unit`` ((n + 1) / 2 -> 8 bit), ``kitti_flow``;
    empty: chosen by dtype and shape. ``show``: ``metric``, ``ids``, ``half_unit``, ``srgb``, ``flow``,
    ``mask``, ``as_stored``; empty: chosen by dtype and shape. ``smooth``: gallery thumbnails resample it
    with interpolation (continuous values; uint8 color images are too). ``option``: the boolean renderer
    parameter that turns the pass on (renderer modules declare one per option, documented by
    ``option_doc``; the hint is then 'set <option>: true on the renderer' unless ``request`` says more).
    """

    key: str
    dtype: str
    channels: int | None
    doc: str
    request: str
    compute: Compute | None
    needs: tuple[str, ...] = ("raster",)
    units: str = ""
    frame: str = ""
    background: str = "0"
    pattern: str = ""
    hdf5: str = ""
    blenderproc: str = ""
    png: str = ""
    exr_channels: tuple[str, ...] | None = None
    show: str = ""
    on_request: bool = False
    with_keys: tuple[str, ...] = ()
    rank: int = 1  # contact sheets: lower first
    smooth: bool = False
    option: str = ""
    option_doc: str = ""

    def shape(self, width: int, height: int) -> tuple[int, ...]:
        """Per-keypoint shape at ``width`` x ``height`` pixels."""
        if self.channels is None:
            return ()
        return (height, width, self.channels) if self.channels else (height, width)

    @property
    def is_image(self) -> bool:
        return self.channels is not None


def _raster(function: Callable[[Any], np.ndarray]) -> Compute:
    return lambda frame, key: function(frame.raw)


def _segmap(frame: "KeypointFrame", key: str) -> Any:
    if key == "category_id_segmaps" and frame.raw.category is not None:  # drawn as a target of its own
        return raster.category_ids(frame.raw)
    return frame.tables.luts[key[: -len("_segmaps")]][frame.raw.instance]


def _flow(step: int, part: int) -> Compute:
    def compute(frame: "KeypointFrame", key: str) -> np.ndarray:
        def make() -> tuple[np.ndarray, np.ndarray]:
            other, depth = frame.neighbour_depth(step)
            if other is None:
                return optical_flow(frame.raw, frame.intrinsics, frame.cam2world, None, None)
            return optical_flow(frame.raw, frame.intrinsics, frame.cam2world, other, depth, frame.object_motion(step),
                                frame.neighbour_intrinsics(step))
        return frame.shared(("flow", step), make)[part]
    return compute


def _flow_specs(direction: str, step: int) -> tuple[PassSpec, PassSpec]:
    option = {"option": "render_flow", "option_doc": "write forward/backward optical flow [px] between consecutive "
              "keypoints with *_flow_occluded masks"}
    return (PassSpec(f"{direction}_flow", "float32", 2, f"image motion (u, v) of each pixel's surface point to "
                     f"keypoint i {'+' if step > 0 else '-'} 1 (static scene); 0 where undefined", "",
                     _flow(step, 0), ("raster", "neighbours"), units="px", png="kitti_flow",
                     exr_channels=("u", "v"), show="flow", **option),
            PassSpec(f"{direction}_flow_occluded", "uint8", 0, "1 where the point is not visible in the other "
                     "keypoint (or there is none)", "", _flow(step, 1), ("raster", "neighbours"),
                     background="1", show="mask", **option))


_COLOR = "render color with renderer.RgbRenderer before this writer"
_SPECS = (
    PassSpec("depth", "float32", 0, "distance along the optical axis (camera z)", "", _raster(raster.depth),
             units="m", background="depth_background (inf by default)", pattern="*depth", png="millimetres",
             show="metric", option="render_depth", option_doc="write 'depth' (camera z, m)"),
    PassSpec("distance", "float32", 0, "Euclidean distance from the camera centre", "", _raster(raster.distance),
             units="m", background="depth_background", pattern="*distance", hdf5="derived_from_depth",
             png="millimetres", show="metric", option="render_distance",
             option_doc="write 'distance' (Euclidean from the camera centre, m)"),
    PassSpec("normals", "float32", 3, "unit surface normal facing the camera, xyz in [-1, 1]", "",
             _raster(raster.normals), frame="camera (OpenCV) or world (normals_space)", background="(0, 0, 0)",
             pattern="normals*", hdf5="octahedral", blenderproc="blender_half_unit", png="half_unit",
             exr_channels=("X", "Y", "Z"), show="half_unit", smooth=True, option="render_normals",
             option_doc="write 'normals' (unit, facing the camera)"),
    PassSpec("<attribute>_segmaps", "int32", 0, "the object's numeric attribute (category_id_segmaps: its "
             "category_id)", "add 'class' (category_id) or the attribute to map_by of the renderer", _segmap,
             pattern="*_segmaps", show="ids"),
    PassSpec("instance_segmaps", "int32", 0, "instance id 1..N, stable across keypoints", INSTANCE_HINT,
             _raster(raster.instance_ids), show="ids"),
    PassSpec("instance_attribute_maps", "json", None, "[{idx, category_id, name, custom attributes}] of each "
             "instance in the map, by id", INSTANCE_HINT, lambda frame, key: frame.tables.visible(frame.raw.instance)),
    PassSpec("albedo", "float32", 3, "diffuse base color / texture at each pixel centre", "",
             lambda frame, key: frame.raster.albedo.render(frame.cam2world), ("albedo",), units="linear RGB",
             background="the world color", png="srgb", show="srgb", smooth=True, option="render_albedo",
             option_doc="write 'albedo': linear base color / texture at each pixel"),
    PassSpec("diffuse_color", "float32", 3, "Cycles' Diffuse Color pass (DiffCol) at each pixel centre: the "
             "Principled BSDF's diffuse weight (base color less what its specular, metal, transmission, coat and "
             "sheen layers take from the view direction) plus its sheen albedo", "",
             lambda frame, key: frame.raster.diffuse_color.render(frame.cam2world, background=(0.0, 0.0, 0.0)),
             ("diffuse_color",), units="linear RGB", png="srgb", show="srgb", smooth=True,
             option="render_diffuse_color",
             option_doc="write 'diffuse_color': Blender's Diffuse Color pass (what the specular layers leave of "
             "the base color) at each pixel"),
    PassSpec("nocs", "float32", 3, "normalized object coordinates in [0, 1] (NOCS paper)", "",
             lambda frame, key: nocs(frame.raw, frame.intrinsics, frame.cam2world, frame.scene), show="as_stored",
             smooth=True, option="render_nocs", option_doc="write 'nocs': normalized object coordinates in [0, 1]"),
    PassSpec("object_coordinates", "float32", 3, "the surface point in its object's local (mesh) frame", "",
             lambda frame, key: object_coordinates(frame.raw, frame.intrinsics, frame.cam2world, frame.scene),
             units="m", background="NaN", show="as_stored"),
    PassSpec("object_records", "json", None, "per object in view: obj2cam, 3D box, visible and amodal 2D boxes, "
             "pixel counts, visible fraction (render/raster/object_records.py)", "",
             lambda frame, key: object_records(frame), ("raster", "silhouettes"), option="render_object_records",
             option_doc="write 'object_records' per keypoint: object-to-camera poses, 3D boxes, visible and "
             "amodal 2D boxes, pixel counts, visible fractions"),
    *_flow_specs("forward", 1), *_flow_specs("backward", -1),
    PassSpec("amodal_masks", "object", None, "{instance id: (H, W) bool full silhouette inside the image}",
             INSTANCE_HINT, amodal_masks, ("raster", "silhouettes"), on_request=True,
             with_keys=("instance_segmaps",)),
    PassSpec("visible_fractions", "object", None, "{instance id: {px_count_all, px_count_visib, visib_fract}}",
             INSTANCE_HINT, visible_fractions, ("raster", "silhouettes"), on_request=True,
             with_keys=("instance_segmaps",)),
    PassSpec("object_boxes", "object", None, "{instance id: {bbox_obj, bbox_visib}} (BOP toolkit boxes)",
             INSTANCE_HINT, object_boxes, ("raster", "silhouettes"), on_request=True,
             with_keys=("instance_segmaps",)),
    PassSpec("colors", "uint8", 3, "path-traced color, sRGB transfer of linear radiance clipped to [0, 1]",
             _COLOR, None, ("path_trace",), units="sRGB", pattern="colors*", show="as_stored", rank=0),
    PassSpec("colors_hdr", "float16", 3, "linear radiance (denoised when colors is)", "set output_hdr: true on "
             "renderer.RgbRenderer", None, ("path_trace",), units="linear RGB", png="srgb", show="srgb", rank=0),
    PassSpec("colors_raw", "uint8", 3, "colors before denoising", "set output_raw: true (with denoise) on "
             "renderer.RgbRenderer", None, ("path_trace",), units="sRGB", show="as_stored", rank=0),
    PassSpec("sample_counts", "uint32", 0, "path-tracing samples each pixel received", "set "
             "output_sample_counts: true on renderer.RgbRenderer", None, ("path_trace",), units="samples"),
)

PASSES: dict[str, PassSpec] = {spec.key: spec for spec in _SPECS}
"""Every pass by output key (``<attribute>_segmaps`` stands for the family)."""

RECORDS: dict[str, str] = {
    "cam_K": "camera", "cam2world": "camera", "cam2world_right": "camera",
    "scene_index": "position", "keypoint_index": "position",
    "object_states": "scene", "light_states": "scene",
}
"""Stored keys that are not passes: per-keypoint camera matrices (not images), a keypoint's position in the
run, and per-scene JSON records."""


def spec(key: str) -> PassSpec:
    """The entry of an output key as renderers name it (``<attr>_segmaps`` keys share one entry)."""
    found = PASSES.get(key) or (PASSES["<attribute>_segmaps"] if key.endswith("_segmaps") else None)
    if found is None:
        raise KeyError(f"no pass '{key}'; known: {sorted(PASSES)}")
    return found


def recognise(stored: str) -> PassSpec | None:
    """The pass a stored key holds: its exact name, else the first entry whose ``pattern`` matches (keys that
    end in 'depth', '<attr>_segmaps', ...); None for keys that are no pass."""
    if stored in PASSES:
        return PASSES[stored]
    return next((s for s in _SPECS if s.pattern and fnmatch.fnmatchcase(stored, s.pattern)), None)


def exact(stored: str) -> PassSpec | None:
    """The pass a stored key holds when it has the pass's own name (storage encodings apply only then)."""
    return PASSES.get(stored) or (PASSES["<attribute>_segmaps"] if stored.endswith("_segmaps") else None)


def hint(key: str) -> str:
    """How to make ``key`` (for 'needs ... which no renderer writes' errors)."""
    found = recognise(key)
    if found is None:
        return f"make a renderer write '{key}'"
    return found.request or f"set {found.option}: true on the renderer"


def layout(key: str, width: int, height: int, **meaning: Any) -> PassLayout:
    """The :class:`~hybridgen.io.frame_sink.PassLayout` of output ``key`` at ``width`` x ``height`` pixels: the
    entry's dtype, shape and units; ``meaning`` adds what depends on the run (background, frame)."""
    entry = spec(key)
    units = {"units": entry.units} if entry.units else {}
    return PassLayout(key, entry.dtype, entry.shape(width, height), **{**units, **meaning})


def color_keys(*, hdr: bool = False, raw: bool = False, sample_counts: bool = False) -> list[str]:
    """The keys the color producer writes: ``colors``, and ``colors_hdr``/``colors_raw``/``sample_counts``
    when asked for (``raw`` only means something with denoising)."""
    flags = {"colors": True, "colors_hdr": hdr, "colors_raw": raw, "sample_counts": sample_counts}
    return [key for key, wanted in flags.items() if wanted]


def pass_options() -> dict[str, list[PassSpec]]:
    """Renderer options that turn passes on -> the passes each turns on, in catalogue order."""
    out: dict[str, list[PassSpec]] = {}
    for entry in _SPECS:
        if entry.option:
            out.setdefault(entry.option, []).append(entry)
    return out


def on_request(key: str) -> bool:
    """Whether ``key`` goes only to the sinks that ask for it (see the module documentation)."""
    found = PASSES.get(key)
    return bool(found and found.on_request)
