"""Silently degraded mesh input made explicit: zero normals recomputed (a notice), missing MTL/texture files
an error (textures: when base color is shown) or, with --lenient, a notice."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.errors import InputError
from hybridgen.io.mesh_loader import load_objects
from hybridgen.io.mesh_references import LENIENT_ENV
from hybridgen.io.texture_needs import require_base_colors


def test_zero_vertex_normals_are_recomputed_from_faces(tmp_path, notice_lines):
    mesh = tmp_path / "zero.obj"
    # two triangles of the plane x + y + z = 1 (Z-up file); vertex 1 has vn 0 0 0, the others the true normal
    mesh.write_text("v 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 -1\n"
                    "vn 0 0 0\nvn 0.57735 0.57735 0.57735\n"
                    "f 1//1 2//2 3//2\nf 1//1 4//2 2//2\n")
    (obj,) = load_objects(mesh, up_axis="Z")
    np.testing.assert_allclose(obj.vertex_normals, np.full((4, 3), 1 / np.sqrt(3)), atol=1e-5)
    assert any("1 zero-length vertex normal(s) recomputed" in line for line in notice_lines)


def test_missing_texture_named_by_an_mtl(tmp_path, notice_lines, monkeypatch):
    (tmp_path / "skin.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd -s 1 1 1 textures/skin.png\n")
    mesh = tmp_path / "thing.obj"
    mesh.write_text("mtllib skin.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\nf 1/1 2/2 3/3\n")
    # the mesh loads (labels do not need its texture); showing its base color stops (texture_needs)
    objects = load_objects(mesh)
    assert [o.material.missing_files for o in objects] == [(str(tmp_path / "textures/skin.png"),)]
    with pytest.raises(InputError, match=r"missing file\(s\) it names: '.*textures/skin.png'.*--lenient"):
        require_base_colors(objects)
    monkeypatch.setenv(LENIENT_ENV, "1")
    require_base_colors(objects)
    assert any("textures/skin.png" in line for line in notice_lines)
