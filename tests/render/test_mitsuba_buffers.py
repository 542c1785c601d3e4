"""Mesh buffers handed to Mitsuba (render/mitsuba_scene.jit_buffer): the same values, flat, starting on a
64-byte boundary wherever NumPy put the source - so the kernels Dr.Jit traces, and their cache keys, do not
depend on where malloc placed an array (warm runs hit the kernel cache)."""
from __future__ import annotations

import numpy as np
import pytest

import hybridgen as hg
from hybridgen.render.pathtrace.mitsuba_scene import JIT_ALIGNMENT, jit_buffer, mesh_shape
from hybridgen.render.pathtrace.mitsuba_variant import activate, choose_variant
from tests.conftest import REPO


@pytest.mark.parametrize("dtype", [np.float32, np.uint32])
def test_jit_buffer_is_an_aligned_flat_copy(dtype):
    rng = np.random.default_rng(3)
    source = rng.uniform(0, 1000, (7 * 64 + 3, 3))
    for offset in range(4):  # sources starting at every 4-byte offset of a line, and transposed (strided) ones
        for array in (source[offset:], source[offset:].T):
            out = jit_buffer(array, dtype)
            assert out.ctypes.data % JIT_ALIGNMENT == 0 and out.flags.c_contiguous and out.dtype == dtype
            assert np.array_equal(out, np.asarray(array, dtype=dtype).ravel())
    assert jit_buffer(np.zeros((0, 3)), np.float32).size == 0


def test_mesh_shape_holds_the_objects_buffers():
    activate(choose_variant(None))
    import mitsuba as mi

    (obj,) = hg.load_objects(REPO / "configs/assets/crate.obj", name="crate", category_id=1,
                             local2world=hg.object_pose([0.5, -0.2, 0.1], [0.3, 0.2, 0.1]))
    params = mi.traverse(mesh_shape(obj))
    np.testing.assert_array_equal(np.array(params["vertex_positions"]), obj.world_vertices().astype(np.float32).ravel())
    np.testing.assert_array_equal(np.array(params["faces"]), obj.faces.astype(np.uint32).ravel())
    uv = np.array(obj.uvs, np.float32)
    uv[:, 1] = 1.0 - uv[:, 1]
    np.testing.assert_array_equal(np.array(params["vertex_texcoords"]), uv.ravel())
