"""The passes made from a raster readback alone (:class:`~hybridgen.render.readback.RasterOutput`): depth,
distance, normals and the two built-in id maps. :meth:`~hybridgen.render.raster.RasterView.render` returns
them by name; the catalogue (:mod:`hybridgen.render.passes`) binds them to their output keys."""
from __future__ import annotations

from typing import Callable

import numpy as np

from .readback import RasterOutput


def depth(out: RasterOutput) -> np.ndarray:
    """Camera z (m), ``depth_background`` where nothing was hit."""
    values = np.array(out.normal_depth[..., 3], dtype=np.float32)
    values[~out.hit] = out.depth_background
    return values


def distance(out: RasterOutput) -> np.ndarray:
    """Euclidean distance from the camera centre (m), ``depth_background`` where nothing was hit."""
    dist = out.normal_depth[..., 3] * out.ray_lengths
    dist[~out.hit] = out.depth_background
    return dist.astype(np.float32, copy=False)


def normals(out: RasterOutput) -> np.ndarray:
    """Unit normals (a view: writers copy it, off the render thread, when they store it)."""
    return out.normal_depth[..., :3]


def instance_ids(out: RasterOutput) -> np.ndarray:
    """Instance ids as int32, 0 where nothing was hit."""
    return out.instance.astype(np.int32)


def category_ids(out: RasterOutput) -> np.ndarray:
    """The category_id of the object seen at each pixel (0: background, or an object without one)."""
    return out.category_lut[out.instance]


RASTER_PASSES: dict[str, Callable[[RasterOutput], np.ndarray]] = {
    "depth": depth, "distance": distance, "normals": normals,
    "instance_segmaps": instance_ids, "category_id_segmaps": category_ids,
}
"""Output key -> the function making it from a readback alone."""
