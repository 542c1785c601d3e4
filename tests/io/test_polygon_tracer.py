"""The vectorised COCO polygon tracer: exact pixel outlines on large fragmented masks (checked by
pycocotools rasterizing them back) and loops in the documented order."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from hybridgen.io.mask_encoding import mask_to_polygons, outline_loops, signed_area


def test_fragmented_mask_rasterizes_back_exactly():
    mask_utils = pytest.importorskip("pycocotools.mask")
    rng = np.random.default_rng(3)
    mask = (ndimage.gaussian_filter(rng.random((120, 160)), 3) > 0.5) ^ (rng.random((120, 160)) < 0.05)
    polygons = mask_to_polygons(mask)
    assert len(polygons) > 100
    merged = mask_utils.merge(mask_utils.frPyObjects(polygons, *mask.shape))
    np.testing.assert_array_equal(mask_utils.decode(merged).astype(bool),
                                  ndimage.binary_fill_holes(mask, np.ones((3, 3))))


def test_loops_of_a_ring_and_corner_touching_pixels():
    mask = np.zeros((6, 7), bool)
    mask[1:5, 1:5] = True
    mask[2:4, 2:4] = False  # a hole
    mask[5, 5] = True  # touches the ring only at a corner: its own loop
    loops = outline_loops(mask)
    assert [loop.tolist() for loop in loops] == [
        [[1, 1], [5, 1], [5, 5], [1, 5]],  # outer, clockwise on screen, from its smallest corner
        [[2, 2], [2, 4], [4, 4], [4, 2]],  # the hole, the other way
        [[5, 5], [6, 5], [6, 6], [5, 6]],
    ]
    assert [signed_area(loop) for loop in loops] == [16.0, -4.0, 1.0]
    assert mask_to_polygons(mask) == [[1.0, 1.0, 5.0, 1.0, 5.0, 5.0, 1.0, 5.0],
                                      [5.0, 5.0, 6.0, 5.0, 6.0, 6.0, 5.0, 6.0]]
    assert mask_to_polygons(np.zeros((4, 4), bool)) == [] and outline_loops(np.zeros((0, 3), bool)) == []
