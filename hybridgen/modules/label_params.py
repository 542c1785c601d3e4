"""Label options shared by every renderer module (docs/conventions.md section 6), declared once."""
from __future__ import annotations

import math
from typing import Any, Iterable

from ..config.schema import Param
from ..errors import HybridgenError
from ..io.renamed_sink import check_output_keys
from ..render.passes import pass_options
from ..render.raster.label_request import LabelRequest, parse_map_by
from ..render.raster.raster_view import NORMAL_SPACES


def _map_by_check(value: Any) -> str | None:
    items = [value] if isinstance(value, str) else value
    if not all(isinstance(v, str) and v for v in items):
        return f"must be 'class', 'instance', an attribute name or a list of them, got {value!r}"
    return None


def _background_check(value: Any) -> str | None:
    return None if isinstance(value, (int, float)) or value in ("inf", ".inf") else \
        f"must be a number or inf, got {value!r}"


def label_params(*, depth: bool, normals: bool, map_by: Any) -> tuple[Param, ...]:
    """The label keys with this renderer's defaults: one boolean per pass option of the catalogue
    (:func:`hybridgen.render.passes.pass_options`), then the options that shape the passes."""
    defaults = {"render_depth": depth, "render_normals": normals}
    return (
        *(Param(option, "bool", defaults.get(option, False), doc=entries[0].option_doc)
          for option, entries in pass_options().items()),
        Param("normals_space", "str", "camera", choices=NORMAL_SPACES, doc="axes of 'normals': camera (OpenCV) "
              "or world"),
        Param("map_by", "str|list|null", map_by, check=lambda v: None if v is None else _map_by_check(v),
              doc="segmentation: class -> category_id_segmaps, instance -> instance_segmaps + "
              "instance_attribute_maps, <attr> -> <attr>_segmaps; null: none"),
        Param("depth_background", "float|str", math.inf, "m", "depth/distance of pixels that hit nothing",
              check=_background_check),
        Param("output_keys", "dict|null", None, check=check_output_keys, doc="store passes under other names, "
              "{pass: name} (e.g. {colors: rgb, depth: depth_m}); every writer sees the new name "
              "(BlenderProc's output_key / *_output_key)"),
    )


def label_request(config: dict[str, Any]) -> LabelRequest:
    """The LabelRequest a renderer module's validated config asks for."""
    background = config["depth_background"]
    return LabelRequest.from_options(
        config, map_by=[] if config["map_by"] is None else parse_map_by(config["map_by"]),
        depth_background=math.inf if isinstance(background, str) else float(background),
        normals_space=config["normals_space"])


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
