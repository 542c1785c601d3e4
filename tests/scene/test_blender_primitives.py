"""hybridgen.scene.blender_primitives against Blender 4.2's ``primitive_*_add`` meshes measured with bpy
(tools/blender_primitives.py --store): per case the vertex and polygon counts, and for up to 40 polygons spread
over Blender's list the polygon with the same corners in the same order (1e-5 m) and the same UV per corner (1e-5)
- the cube, the plane, UV spheres (the default 32 x 16 and five other sizes), cylinders and cones with NGON,
TRIFAN and no caps, pointed and truncated."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hybridgen.errors import InputError
from hybridgen.scene import blender_primitives

TABLE = json.loads((Path(__file__).parent / "data" / "blender_primitives.json").read_text())


@pytest.mark.parametrize("name", list(TABLE))
def test_polygons_and_uvs_equal_blenders(name: str) -> None:
    case = TABLE[name]
    mesh = getattr(blender_primitives, case["kind"])(**case["arguments"])
    sizes = np.diff(mesh.starts)
    assert (len(mesh.positions), len(sizes)) == (case["vertices"], case["polygons"])
    assert len(np.unique(mesh.positions.round(6), axis=0)) == len(mesh.positions)  # one vertex per position
    polygons = [mesh.positions[mesh.corners[a:b]] for a, b in zip(mesh.starts[:-1], mesh.starts[1:])]
    uvs = [mesh.attributes["uvs"][a:b] for a, b in zip(mesh.starts[:-1], mesh.starts[1:])]
    for stored in case["sample"]:
        corners = np.asarray(stored["corners"])
        match = [i for i, p in enumerate(polygons) if p.shape == corners.shape and np.abs(p - corners).max() < 1e-5]
        assert len(match) == 1, (name, corners)
        np.testing.assert_allclose(uvs[match[0]], stored["uvs"], atol=1e-5, err_msg=name)


def test_default_sphere_is_blenders_32_by_16() -> None:
    mesh = blender_primitives.uv_sphere()
    sizes = np.diff(mesh.starts)
    assert len(mesh.positions) == 32 * 15 + 2 and (sizes == 3).sum() == 64 and (sizes == 4).sum() == 32 * 14
    assert np.allclose(np.linalg.norm(mesh.positions, axis=1), 1.0)
    assert mesh.attributes["uvs"][:, 0].min() == 0.0 and mesh.attributes["uvs"][:, 0].max() == pytest.approx(1.0)


def test_bad_arguments_stop_with_one_line() -> None:
    with pytest.raises(InputError, match="UV sphere needs segments >= 3"):
        blender_primitives.uv_sphere(segments=2)
    with pytest.raises(InputError, match="end_fill_type one of"):
        blender_primitives.cylinder(end_fill_type="QUADS")
