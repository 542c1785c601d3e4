"""Whole-process inputs of the label benchmarks: a labels-only ``hybridgen run`` config of a scene of
tools/label_scenes.py (its meshes written once as files) and the same meshes, intrinsics and poses as a spec for
tools/pyrender_reference.py (tools/bench_labels.py, tools/bench_startup.py). Units: metres, pixels.
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Any

import label_scenes as bs
import numpy as np


def export_assets(name: str, folder: Path) -> list[dict[str, Any]]:
    """The scene's mesh files: the monastery as pybullet_data's OBJ itself; the other scenes written once as
    binary PLY in world coordinates (vertex normals kept where the object has them). Each entry: path,
    category_id, 4x4 pose (identity unless the file is +Y up)."""
    import trimesh

    if name.startswith("monastery"):
        y_up = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
        return [{"path": str(bs.pybullet_data_dir() / "samurai_monastry.obj"), "category_id": 1,
                 "up_axis": "Y", "pose": y_up.tolist()}]
    scene = bs.ALL_SCENES[name]()
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for i, obj in enumerate(scene.objects):
        path = folder / f"{i:03d}.ply"
        if not path.exists():
            normals = None
            if obj.vertex_normals is not None:
                normals = obj.vertex_normals @ np.linalg.inv(obj.local2world[:3, :3])  # inverse transpose
                normals /= np.linalg.norm(normals, axis=1, keepdims=True)
            mesh = trimesh.Trimesh(obj.world_vertices(), obj.faces, vertex_normals=normals, process=False)
            temp = path.with_suffix(".tmp")
            temp.write_bytes(mesh.export(file_type="ply"))
            temp.rename(path)
        entries.append({"path": str(path), "category_id": int(obj.category_id or 1), "up_axis": "Z",
                        "pose": np.eye(4).tolist()})
    return entries


def write_configs(name: str, resolution: str, count: int, folder: Path,
                  render_threads: int | None = None) -> tuple[Path, Path]:
    """A labels-only hybridgen config (depth + normals + class + instance, default HDF5 writer, ``render_threads``
    raster threads; None: SegMapRenderer's default, auto) and the pyrender script's spec: the same meshes,
    intrinsics and ``count`` poses."""
    meshes = export_assets(name, Path(tempfile.gettempdir()) / "hybridgen_bench_assets" / name.split()[0])
    scene = bs.ALL_SCENES[name]()
    width, height = bs.RESOLUTIONS[resolution]
    intr = bs.intrinsics(width, height)
    poses = bs.orbit_poses(scene, count)
    lines = ["global: {all: {output_dir: \"<args:0>\"}}", "modules:",
             "  - {name: main.Initializer, config: {seed: 1}}"]
    for i, entry in enumerate(meshes):
        lines.append(f"  - {{name: loader.ObjLoader, config: {{path: '{entry['path']}', name: m{i}, "
                     f"category_id: {entry['category_id']}, up_axis: {entry['up_axis']}}}}}")
    K = [float(v) for v in intr.K.ravel()]
    lines.append(f"  - name: camera.CameraLoader\n    config:\n      intrinsics: {{resolution_x: {width}, "
                 f"resolution_y: {height}, cam_K: {K}, clip_start: {intr.clip_start}, clip_end: {intr.clip_end}}}\n"
                 "      cam_poses:")
    for pose in poses:
        # source_frame as in BlenderProc: the OpenCV camera's axes in Blender camera axes
        lines.append(f"        - {{cam2world_matrix: {[float(v) for v in pose.ravel()]}, source_frame: [X, -Y, -Z]}}")
    lines.append("  - {name: renderer.SegMapRenderer, config: {render_depth: true, render_normals: true, "
                 "map_by: [class, instance]" + ("" if render_threads is None else f", render_threads: {render_threads}")
                 + "}}")
    lines.append("  - {name: writer.Hdf5Writer}")
    folder.mkdir(parents=True, exist_ok=True)
    stem = f"{name.split()[0]}_{resolution}_{count}_{render_threads or 'default'}t"
    config = folder / f"{stem}.yaml"
    config.write_text("\n".join(lines) + "\n")
    spec = folder / f"{stem}.json"
    spec.write_text(json.dumps({"meshes": meshes, "K": intr.K.tolist(), "resolution": [width, height],
                                "clip": [intr.clip_start, intr.clip_end], "poses": [p.tolist() for p in poses]}))
    return config, spec

