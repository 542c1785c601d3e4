"""MeshObject.clear_custom_splitnormals as Blender 4.2 under BlenderProc: a PLY with (here deliberately wrong) vertex
normals loads smooth with them as custom normals, and clearing them leaves the smooth normals of its faces (on an
icosphere: within 2 degrees of radial, where the file's were ~20 degrees off); a PLY without normals loads flat and
stays flat; normals set by set_shading_mode are not the file's and stay. load_replica clears Replica's."""
from __future__ import annotations

import numpy as np
import trimesh

from writer_session import bproc  # noqa: F401 - the fixture


def _sphere(path, normals: bool) -> None:
    mesh = trimesh.creation.icosphere(subdivisions=2)
    noisy = mesh.vertex_normals + np.random.default_rng(0).normal(0.0, 0.3, mesh.vertices.shape)
    noisy /= np.linalg.norm(noisy, axis=1, keepdims=True)
    trimesh.Trimesh(mesh.vertices, mesh.faces, vertex_normals=noisy, process=False).export(
        str(path), vertex_normal=normals)


def _radial_error_deg(part) -> float:
    radial = part.vertices / np.linalg.norm(part.vertices, axis=1, keepdims=True)
    return float(np.degrees(np.arccos(np.clip((part.vertex_normals * radial).sum(1), -1, 1))).max())


def test_clearing_file_normals(bproc, tmp_path) -> None:  # noqa: F811
    _sphere(tmp_path / "with.ply", True)
    (sphere,) = bproc.loader.load_obj(str(tmp_path / "with.ply"))
    assert sphere.normals_from_file and _radial_error_deg(sphere.parts[0]) > 20
    twin = sphere.duplicate()
    sphere.clear_custom_splitnormals()
    assert not sphere.normals_from_file and _radial_error_deg(sphere.parts[0]) < 2.0
    assert _radial_error_deg(twin.parts[0]) > 20  # the duplicate keeps its own
    twin.set_shading_mode("AUTO", 5.0)
    normals = twin.parts[0].vertex_normals.copy()
    twin.clear_custom_splitnormals()
    assert np.array_equal(twin.parts[0].vertex_normals, normals)
    _sphere(tmp_path / "without.ply", False)
    (flat,) = bproc.loader.load_obj(str(tmp_path / "without.ply"))
    flat.clear_custom_splitnormals()
    assert flat.parts[0].vertex_normals is None


def test_load_replica_clears_the_file_normals(bproc, tmp_path) -> None:  # noqa: F811
    (tmp_path / "room").mkdir()
    _sphere(tmp_path / "room" / "mesh.ply", True)
    (room,) = bproc.loader.load_replica(str(tmp_path), "room")
    assert _radial_error_deg(room.parts[0]) < 2.0
