"""Packed label targets: the raster pass writes each label straight in the form it is stored in.

The default label draw writes two render targets - RGBA32F (unit normal xyz, camera z) and R32UI (instance id),
20 bytes per pixel - and the writer then derives what it stores on the CPU (depth with its background filled,
octahedral uint16 normals, ids narrowed to the smallest integer type). A :class:`LabelTargets` draw writes those
stored forms directly, one render target per stored dataset, so that each ``glReadPixels`` lands in the
contiguous array the compressor reads (no copy, no per-pixel numpy pass):

* location 0, R32F: camera z (m) - the same float32 the default draw writes - and ``depth_background`` where
  nothing is hit (the attachment is cleared to it; the id targets are cleared to 0 separately);
* location 1, RG16UI (only when ``octahedral_normals``): the octahedral code of the unit normal, computed in the
  fragment shader with the operations of :func:`hybridgen.io.label_encoding.encode_octahedral` in the same order
  (float32, correctly rounded division and round-half-even on llvmpipe: bit-identical codes, tested). On GPUs
  whose division is not correctly rounded a code may round the other way where the value lies within ~1e-7 of a
  rounding midpoint; the stated bound (``OCTAHEDRAL_MAX_ERROR_RAD``) still holds;
* then the instance id and, when asked, the category id, each in an unsigned integer target of the smallest
  width (8, 16, 32 bits) that holds the scene's values.

Ids and depth are exact: the same values as the default draw, in the stored dtype.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

_UINT_FORMATS = {np.dtype(np.uint8): "u1", np.dtype(np.uint16): "u2", np.dtype(np.uint32): "u4"}


def unsigned_target_dtype(high: int) -> np.dtype | None:
    """The narrowest unsigned integer dtype a render target can hold values 0..``high`` in (None: none can)."""
    for dtype in _UINT_FORMATS:
        if high <= np.iinfo(dtype).max:
            return dtype
    return None


@dataclass(frozen=True)
class LabelTargets:
    """Which packed targets one label draw writes (see the module documentation)."""

    octahedral_normals: bool
    instance_dtype: np.dtype
    category_dtype: np.dtype | None = None  # None: category ids come from the instance map on the CPU
    encoded: tuple[tuple[str, str], ...] = ()  # (output key, storage tag) the sinks take straight from the draw

    def attachments(self) -> list[tuple[str, int, str]]:
        """``(name, components, moderngl dtype)`` of each colour attachment, in location order."""
        out = [("depth", 1, "f4")]
        if self.octahedral_normals:
            out.append(("normal_codes", 2, "u2"))
        out.append(("instance", 1, _UINT_FORMATS[np.dtype(self.instance_dtype)]))
        if self.category_dtype is not None:
            out.append(("category", 1, _UINT_FORMATS[np.dtype(self.category_dtype)]))
        return out

    def defines(self) -> str:
        """The preprocessor lines that select these targets in ``labels.frag``."""
        names = [name for name, _, _ in self.attachments()]
        lines = ["#define PACKED_TARGETS"]
        if self.octahedral_normals:
            lines += ["#define OCTAHEDRAL_NORMALS", f"#define LOCATION_NORMAL_CODES {names.index('normal_codes')}"]
        lines.append(f"#define LOCATION_INSTANCE {names.index('instance')}")
        if self.category_dtype is not None:
            lines += ["#define CATEGORY_TARGET", f"#define LOCATION_CATEGORY {names.index('category')}"]
        return "\n".join(lines)


def packed_targets(request: Any, tables: Any, scene: Any, accepted: dict[str, str]) -> LabelTargets | None:
    """The packed targets of a :class:`~hybridgen.render.raster.label_request.LabelRequest`'s passes, or None where the
    default targets are needed: normals are asked for but some sink takes them only as float32.

    ``tables``: the request's :class:`~hybridgen.render.raster.keypoint_frame.LabelTables`; ``accepted``: output key ->
    the storage tag every sink receiving it stores (octahedral normals, narrowed ids): those passes are handed
    on as drawn; distance, when every sink derives it from depth on read, is not computed."""
    from ...io.array_encoding import DERIVED_DISTANCE, NARROWED, OCTAHEDRAL, storage_tag

    if request.normals and accepted.get("normals") != OCTAHEDRAL:
        return None
    instance_dtype = unsigned_target_dtype(max((o.instance_id for o in scene.objects), default=0))
    if instance_dtype is None:
        return None
    category_dtype = None
    lut = tables.luts.get("category_id")
    if lut is not None and len(lut) and int(lut.min()) >= 0:
        category_dtype = unsigned_target_dtype(int(lut.max()))
    encoded = [("normals", OCTAHEDRAL)] if request.normals else []
    for key, dtype in (("instance_segmaps", instance_dtype), ("category_id_segmaps", category_dtype)):
        tag = storage_tag(NARROWED, dtype, np.dtype(np.int32)) if dtype is not None else None
        if tag is not None and accepted.get(key) == tag:
            encoded.append((key, tag))
    if request.distance and accepted.get("distance") == DERIVED_DISTANCE:  # the sinks derive it from depth
        encoded.append(("distance", DERIVED_DISTANCE))
    return LabelTargets(bool(request.normals), instance_dtype, category_dtype, tuple(encoded))
