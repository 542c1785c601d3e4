"""Blender's shading modes: FLAT drops vertex normals, SMOOTH gives the corner-angle-weighted normal per vertex
position (an icosphere's normals point radially, a cube's along its diagonals), AUTO keeps edges sharper than
the angle sharp (a cube stays faceted, a fine sphere turns smooth); BlenderProc's cf_set_shading on loaders and
EntityManipulator reaches the objects."""
from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh

from hybridgen.config.notices import set_sink
from hybridgen.scene.shading import shade
from tests.config.test_blenderproc_modules import run_config_text


def _radial_error(vertices: np.ndarray, normals: np.ndarray) -> float:
    radial = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    return float(np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", radial, normals), -1, 1))).max())


def test_flat_smooth_and_auto_on_a_sphere_and_a_cube():
    sphere = trimesh.creation.icosphere(subdivisions=3)
    split = sphere.vertices[sphere.faces].reshape(-1, 3)  # every corner its own vertex (as files split seams)
    faces = np.arange(len(split)).reshape(-1, 3)
    assert shade(split, faces, "FLAT").vertex_normals is None
    smooth = shade(split, faces, "SMOOTH")
    assert _radial_error(smooth.vertices, smooth.vertex_normals) < 1.0  # welded across the split corners
    auto = shade(split, faces, "AUTO", 30.0)  # neighbouring faces ~5 deg apart: all smooth
    assert _radial_error(auto.vertices, auto.vertex_normals) < 1.0
    cube = trimesh.creation.box(extents=[2, 2, 2])
    smooth = shade(np.asarray(cube.vertices), np.asarray(cube.faces), "SMOOTH")
    # each corner's three faces meet at 90 deg with equal angles in total: the normal is the diagonal
    np.testing.assert_allclose(np.abs(smooth.vertex_normals), 1 / np.sqrt(3), atol=1e-9)
    auto = shade(np.asarray(cube.vertices), np.asarray(cube.faces), "AUTO", 30.0, uvs=np.zeros((8, 2)))
    face_normals = np.asarray(cube.face_normals)
    for face, corners in enumerate(auto.faces):  # every corner keeps its face's normal: the cube stays faceted
        np.testing.assert_allclose(auto.vertex_normals[corners], np.tile(face_normals[face], (3, 1)), atol=1e-9)
    assert auto.uvs.shape == (len(auto.vertices), 2)
    auto = shade(np.asarray(cube.vertices), np.asarray(cube.faces), "AUTO", 100.0)  # 90 deg edges now smooth
    np.testing.assert_allclose(np.abs(auto.vertex_normals), 1 / np.sqrt(3), atol=1e-9)
    with pytest.raises(ValueError, match="FLAT, SMOOTH, AUTO"):
        shade(split, faces, "PHONG")


def test_cf_set_shading_on_a_loader_and_on_entity_manipulator(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=2)
    lines = ["o Ball"] + [f"v {x} {z} {-y}" for x, y, z in sphere.vertices]  # file axes: y up
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in sphere.faces]
    (tmp_path / "ball.obj").write_text("\n".join(lines) + "\n")

    def run(modules):
        text = json.dumps({"version": 3, "setup": {"blender_install_path": "/opt/blender"}, "modules": [
            {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}}}, *modules]})
        notices: list[str] = []
        set_sink(notices.append)
        try:
            return run_config_text(tmp_path, text).scene.by_name("Ball"), notices
        finally:
            set_sink(None)

    loaded = {"module": "loader.ObjectLoader", "config": {"path": str(tmp_path / "ball.obj")}}
    plain, _ = run([loaded])
    assert plain.vertex_normals is None  # the file has no normals: flat, as Blender imports it
    smooth, notices = run([{**loaded, "config": {**loaded["config"], "cf_set_shading": "SMOOTH"}}])
    assert _radial_error(smooth.world_vertices(), smooth.vertex_normals) < 2.0
    assert not any("key 'cf_set_shading'" in line for line in notices), notices
    flat, _ = run([{**loaded, "config": {**loaded["config"], "cf_set_shading": "SMOOTH"}},
                   {"module": "manipulators.EntityManipulator", "config": {
                       "selector": {"provider": "getter.Entity", "conditions": {"name": "Ball"}},
                       "cf_set_shading": "FLAT"}}])
    assert flat.vertex_normals is None
