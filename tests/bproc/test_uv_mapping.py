"""MeshObject.add_uv_mapping against Blender: the cylinder and sphere coordinates of a posed unit cube's corners as
Blender 4.2 computes them (``bpy.ops.uv.cylinder_project()`` / ``sphere_project()`` in edit mode without a 3D view,
as BlenderProc calls them: cube at (0.4, -0.2, 0.7), rotation (0.3, -0.2, 0.5), scale (1.5, 0.8, 2.0); measured
values, u modulo 1), and the cube projection of a box against its analytic values."""
from __future__ import annotations

import numpy as np
import pytest

from writer_session import bproc  # noqa: F401 - the fixture

BLENDER_CYLINDER = [(0.05311, 0.33692), (0.40342, -0.01342), (0.11212, 0.66102), (0.37763, 0.31068),
                    (0.87763, 0.68932), (0.61212, 0.33898), (0.90342, 1.01342), (0.55311, 0.66308)]
BLENDER_SPHERE = [(0.05311, 0.42006), (0.40342, 0.214), (0.11212, 0.57891), (0.37763, 0.40684),
                  (0.87763, 0.59316), (0.61212, 0.42109), (0.90342, 0.786), (0.55311, 0.57994)]
"""Per corner of the cube (x, y, z in -0.5 / 0.5, itertools.product order)."""


def _corner_uvs(obj) -> dict[tuple[float, ...], set[tuple[float, float]]]:
    part = obj.parts[0]
    found: dict[tuple[float, ...], set[tuple[float, float]]] = {}
    for vertex, uv in zip(part.vertices, part.uvs):
        found.setdefault(tuple(np.sign(vertex)), set()).add((round(uv[0] % 1, 5) % 1, round(uv[1], 5)))
    return found


@pytest.mark.parametrize("projection, expected", [("cylinder", BLENDER_CYLINDER), ("sphere", BLENDER_SPHERE)])
def test_cylinder_and_sphere_match_blender(bproc, projection: str, expected: list) -> None:  # noqa: F811
    cube = bproc.object.create_primitive("CUBE", size=1.0, location=[0.4, -0.2, 0.7], rotation=[0.3, -0.2, 0.5],
                                         scale=[1.5, 0.8, 2.0])
    cube.add_uv_mapping(projection, overwrite=True)  # the cube primitive has Blender's UV map already
    found = _corner_uvs(cube)
    signs = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    for sign, (u, v) in zip(signs, expected):
        assert len(found[sign]) == 1, found[sign]  # one coordinate per corner (no face crosses the seam here)
        got_u, got_v = next(iter(found[sign]))
        assert got_u == pytest.approx(u, abs=2e-5) and got_v == pytest.approx(v, abs=2e-5)


def test_cube_projection_and_overwrite(bproc) -> None:  # noqa: F811
    box = bproc.object.create_primitive("CUBE", size=1.0, location=[3.0, 0.0, 0.0], scale=[1.0, 1.0, 1.0])
    box.parts[0].vertices = box.parts[0].vertices * np.array([2.0, 1.0, 0.5]) + np.array([1.0, 0.0, 0.0])
    box.add_uv_mapping("cube", overwrite=True)  # over the primitive's own UV map
    part = box.parts[0]
    tri = part.vertices[part.faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    top = np.flatnonzero(normals[:, 2] > 0)[0]  # +z face: u, v from local x, y; centre (1, 0, 0), size 2 m
    corners = part.vertices[part.faces[top]]
    np.testing.assert_allclose(part.uvs[part.faces[top]], 0.5 + (corners[:, :2] - [1.0, 0.0]) / 2.0)
    side = np.flatnonzero(normals[:, 0] > 0)[0]  # +x face: u, v from local y, z
    corners = part.vertices[part.faces[side]]
    np.testing.assert_allclose(part.uvs[part.faces[side]], 0.5 + corners[:, 1:] / 2.0)
    before = part.uvs.copy()
    box.add_uv_mapping("sphere")  # has coordinates: nothing changes without overwrite
    assert np.array_equal(box.parts[0].uvs, before)
    box.add_uv_mapping("sphere", overwrite=True)
    assert not np.array_equal(box.parts[0].uvs, before)
    with pytest.raises(Exception, match="add_uv_mapping\\('smart'\\) is not supported"):
        box.add_uv_mapping("smart")
    with pytest.raises(Exception, match="Unknown projection"):
        box.add_uv_mapping("plane")
