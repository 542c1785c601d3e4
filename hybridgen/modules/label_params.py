"""Label options shared by every renderer module (docs/conventions.md section 6), declared once."""
from __future__ import annotations

import math
from typing import Any, Iterable

from ..config.schema import Param
from ..errors import HybridgenError
from ..io.renamed_sink import check_output_keys
from ..render.label_request import LabelRequest, parse_map_by
from ..render.raster import NORMAL_SPACES


def _map_by_check(value: Any) -> str | None:
    items = [value] if isinstance(value, str) else value
    if not all(isinstance(v, str) and v for v in items):
        return f"must be 'class', 'instance', an attribute name or a list of them, got {value!r}"
    return None


def _background_check(value: Any) -> str | None:
    return None if isinstance(value, (int, float)) or value in ("inf", ".inf") else \
        f"must be a number or inf, got {value!r}"


def label_params(*, depth: bool, normals: bool, map_by: Any) -> tuple[Param, ...]:
    """The label keys with this renderer's defaults."""
    return (
        Param("render_depth", "bool", depth, doc="write 'depth' (camera z, m)"),
        Param("render_distance", "bool", False, doc="write 'distance' (Euclidean from the camera centre, m)"),
        Param("render_normals", "bool", normals, doc="write 'normals' (unit, facing the camera)"),
        Param("normals_space", "str", "camera", choices=NORMAL_SPACES, doc="axes of 'normals': camera (OpenCV) "
              "or world"),
        Param("map_by", "str|list|null", map_by, check=lambda v: None if v is None else _map_by_check(v),
              doc="segmentation: class -> category_id_segmaps, instance -> instance_segmaps + "
              "instance_attribute_maps, <attr> -> <attr>_segmaps; null: none"),
        Param("depth_background", "float|str", math.inf, "m", "depth/distance of pixels that hit nothing",
              check=_background_check),
        Param("render_albedo", "bool", False, doc="write 'albedo': linear base color / texture at each pixel"),
        Param("render_flow", "bool", False, doc="write forward/backward optical flow [px] between consecutive "
              "keypoints with *_flow_occluded masks"),
        Param("render_nocs", "bool", False, doc="write 'nocs': normalized object coordinates in [0, 1]"),
        Param("render_object_records", "bool", False, doc="write 'object_records' per keypoint: object-to-camera "
              "poses, 3D boxes, visible and amodal 2D boxes, pixel counts, visible fractions"),
        Param("output_keys", "dict|null", None, check=check_output_keys, doc="store passes under other names, "
              "{pass: name} (e.g. {colors: rgb, depth: depth_m}); every writer sees the new name "
              "(BlenderProc's output_key / *_output_key)"),
    )


def label_request(config: dict[str, Any]) -> LabelRequest:
    """The LabelRequest a renderer module's validated config asks for."""
    background = config["depth_background"]
    return LabelRequest(
        depth=config["render_depth"], distance=config["render_distance"], normals=config["render_normals"],
        map_by=[] if config["map_by"] is None else parse_map_by(config["map_by"]),
        depth_background=math.inf if isinstance(background, str) else float(background),
        normals_space=config["normals_space"], albedo=config["render_albedo"], flow=config["render_flow"],
        nocs=config["render_nocs"], object_records=config["render_object_records"])


def stored_keys(config: dict[str, Any], extra: Iterable[str] = ()) -> frozenset[str] | None:
    """The keys a renderer module with validated ``config`` stores: its label passes and ``extra`` (e.g.
    ``colors``), under the names its ``output_keys`` give them; None when its label options are invalid (the
    renderer reports that when it runs)."""
    try:
        written = {layout.key for layout in label_request(config).layouts(1, 1)}
    except HybridgenError:
        return None
    written.update(extra)
    names = config.get("output_keys") or {}
    return frozenset(names.get(key, key) for key in written)
