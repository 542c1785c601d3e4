"""PLY meshes shade as Blender 4.2's importer (``bpy.ops.wm.ply_import``, which BlenderProc 2.8's ``load_obj``
calls) shades them - measured with pip's bpy 4.2.0 on an icosphere: a PLY with vertex normals (``nx ny nz``)
imports with every face smooth and the file's normals as custom normals; a PLY without them imports with every face
flat. hybridgen keeps a file's normals as the mesh's vertex normals and shades a mesh without them flat."""
from __future__ import annotations

import numpy as np
import trimesh

import hybridgen as hg


def _write(folder, name: str, normals: bool) -> str:
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    path = folder / name
    path.write_bytes(trimesh.exchange.ply.export_ply(sphere, vertex_normal=normals))
    return str(path)


def _normals_image(mesh: str) -> tuple[np.ndarray, np.ndarray]:
    scene = hg.Scene()
    for obj in hg.load_objects(mesh, category_id=1):
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.6, 48, 48)
    cam2world = hg.look_at([0, -3, 0], [0, 0, 0])
    out = hg.RasterView(scene).render(cam2world, ["normals", "instance_segmaps"])
    return out["normals"], out["instance_segmaps"] > 0


def test_a_ply_with_normals_is_smooth_with_the_files_normals(gl_context, tmp_path):
    mesh = _write(tmp_path, "smooth.ply", normals=True)
    (obj,) = hg.load_objects(mesh, category_id=1)
    assert obj.vertex_normals is not None
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    np.testing.assert_allclose(obj.vertex_normals, sphere.vertex_normals, atol=1e-6)  # the file's, as stored
    normals, hit = _normals_image(mesh)
    # interpolated vertex normals vary from pixel to pixel: nearly every hit pixel has its own normal
    assert len(np.unique(np.round(normals[hit], 4), axis=0)) > 0.8 * hit.sum()


def test_a_ply_without_normals_is_flat(gl_context, tmp_path):
    mesh = _write(tmp_path, "flat.ply", normals=False)
    (obj,) = hg.load_objects(mesh, category_id=1)
    assert obj.vertex_normals is None
    normals, hit = _normals_image(mesh)
    # one normal per visible face: far fewer distinct normals than pixels, each a face normal of the mesh
    distinct = np.unique(np.round(normals[hit], 4), axis=0)
    assert len(distinct) < 0.3 * hit.sum()
    faces = obj.face_normals  # camera at -Y looking at +Y: camera (x right, y down, z forward) = world (x, -z, y)
    in_camera = np.stack([faces[:, 0], -faces[:, 2], faces[:, 1]], axis=1)
    nearest = np.min(np.linalg.norm(distinct[:, None, :] - in_camera[None, :, :], axis=2), axis=1)
    assert nearest.max() < 1e-3
