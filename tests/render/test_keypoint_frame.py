"""KeypointFrame / LabelTables helpers: the ids present in a map (instance_attribute_maps lists them)."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.render.raster.keypoint_frame import present_ids


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.uint32, np.int32])
def test_present_ids_are_the_distinct_values_of_any_map(dtype):
    rng = np.random.default_rng(3)
    blocks = rng.integers(0, 200, size=(12, 16)).astype(dtype)
    piecewise = np.kron(blocks, np.ones((40, 40), dtype))  # runs of 40: the run-start path
    piecewise[0, 0] = 7  # a value only in the first pixel
    piecewise[-1, -1] = 199  # ... only in the last pixel
    piecewise[100, 333] = 250  # ... in one pixel inside a run
    noise = rng.integers(0, 60_000 if dtype != np.uint8 else 255, size=(48, 64)).astype(dtype)  # whole count
    for ids in (piecewise, noise, piecewise[:, ::-1], np.zeros((5, 4), dtype), np.full((1, 1), 3, dtype)):
        found = present_ids(ids)
        np.testing.assert_array_equal(found, np.unique(ids))
        assert found.dtype == np.intp
    assert present_ids(np.zeros((0, 4), dtype)).size == 0
