"""The passes made from a raster readback alone (:class:`~hybridgen.render.raster.readback.RasterOutput`): depth,
distance, normals and the two built-in id maps. :meth:`~hybridgen.render.raster.raster_view.RasterView.render` returns
them by name; the catalogue (:mod:`hybridgen.render.passes`) binds them to their output keys.

From a packed readback (:mod:`hybridgen.render.raster.label_targets`) depth is the read-back array itself, and normals
and ids are handed on in their stored form (:class:`~hybridgen.io.label_encoding.EncodedArray`) where the
readback says the sinks take it (``encoded``); otherwise every pass has its documented dtype.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ...io.array_encoding import DERIVED_DISTANCE, NARROWED, OCTAHEDRAL, EncodedArray, decode_octahedral, storage_tag
from .readback import RasterOutput


def depth(out: RasterOutput) -> np.ndarray:
    """Camera z (m), ``depth_background`` where nothing was hit."""
    if out.packed:
        return out.depth_image  # background written by the draw; a fresh array per keypoint
    values = np.array(out.z, dtype=np.float32)
    values[~out.hit] = out.depth_background
    return values


def distance(out: RasterOutput) -> Any:
    """Euclidean distance from the camera centre (m), ``depth_background`` where nothing was hit; an empty
    ``derived_from_depth`` :class:`~hybridgen.io.label_encoding.EncodedArray` where every sink derives it from
    depth on read (``encoded``)."""
    if out.encoded.get("distance") == DERIVED_DISTANCE:
        return EncodedArray(np.empty(0, np.float32), DERIVED_DISTANCE)
    dist = out.z * out.ray_lengths
    dist[~out.hit] = out.depth_background
    return dist.astype(np.float32, copy=False)


def normals(out: RasterOutput) -> Any:
    """Unit normals (a view: writers copy it, off the render thread, when they store it); from a packed
    readback the octahedral codes (decoded where the sinks do not store them)."""
    if not out.packed:
        return out.normal_depth[..., :3]
    assert out.normal_codes is not None, "normals were not drawn"
    if out.encoded.get("normals") == OCTAHEDRAL:
        return EncodedArray(out.normal_codes, OCTAHEDRAL)
    return decode_octahedral(out.normal_codes)


def _ids(out: RasterOutput, key: str, ids: np.ndarray) -> Any:
    tag = storage_tag(NARROWED, ids.dtype, np.dtype(np.int32))
    if out.encoded.get(key) == tag:
        return EncodedArray(ids, tag)
    return ids.astype(np.int32)


def instance_ids(out: RasterOutput) -> Any:
    """Instance ids as int32, 0 where nothing was hit."""
    return _ids(out, "instance_segmaps", out.instance)


def category_ids(out: RasterOutput) -> Any:
    """The category_id of the object seen at each pixel (0: background, or an object without one)."""
    if out.category is not None:
        return _ids(out, "category_id_segmaps", out.category)
    return out.category_lut[out.instance]


RASTER_PASSES: dict[str, Callable[[RasterOutput], Any]] = {
    "depth": depth, "distance": distance, "normals": normals,
    "instance_segmaps": instance_ids, "category_id_segmaps": category_ids,
}
"""Output key -> the function making it from a readback alone."""
