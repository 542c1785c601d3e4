"""MeshObject.set_origin as Blender's origin_set: POINT, CENTER_OF_MASS (area-weighted surface centroid) and
CENTER_OF_VOLUME (the enclosed volume's centroid: a cone's lies a quarter of its height above the base, and trimesh's
mass centre agrees on a tilted, offset one) move the origin and never the geometry; an unknown mode is one line."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.errors import InputError
from writer_session import bproc  # noqa: F401 - the fixture


def _world_vertices(obj) -> np.ndarray:
    local = obj.local_vertices()
    return local @ obj.get_local2world_mat()[:3, :3].T + obj.get_local2world_mat()[:3, 3]


def test_center_of_volume_of_a_cone(bproc) -> None:  # noqa: F811
    cone = bproc.object.create_primitive("CONE")  # radius 1, depth 2: base at z = -1, apex at z = 1
    before = _world_vertices(cone)
    origin = cone.set_origin(mode="CENTER_OF_VOLUME")
    assert np.allclose(origin, [0.0, 0.0, -0.5], atol=1e-9)
    assert np.allclose(_world_vertices(cone), before, atol=1e-12)
    assert np.allclose(cone.get_location(), origin)


def test_center_of_volume_matches_trimesh(bproc) -> None:  # noqa: F811
    cone = bproc.object.create_primitive("CONE", location=[0.3, -1.0, 2.0], rotation=[0.4, 0.2, 1.0],
                                         scale=[1.0, 2.0, 0.5])
    local = cone.mesh_as_trimesh().center_mass  # trimesh's volume centroid, in the local frame
    expected = (cone.get_local2world_mat() @ np.append(local, 1.0))[:3]
    before = _world_vertices(cone)
    assert np.allclose(cone.set_origin(mode="CENTER_OF_VOLUME"), expected, atol=1e-9)
    assert np.allclose(_world_vertices(cone), before, atol=1e-9)
    # the surface centroid is another point: lateral area pi sqrt(5) at z = -1/3, the base disc pi at z = -1
    surface = bproc.object.create_primitive("CONE").set_origin(mode="CENTER_OF_MASS")
    assert surface[2] == pytest.approx((np.sqrt(5) * -1 / 3 - 1) / (np.sqrt(5) + 1), abs=0.01)
    with pytest.raises(InputError, match="No such mode: MIDDLE"):
        cone.set_origin(mode="MIDDLE")
