"""The label benchmarks' competitor: the script a user would write with pyrender - load the same mesh files with
trimesh, render depth + segmentation (colour-coded ids, decoded) of the same poses, write nothing. Run as its own
process by tools/bench_labels.py, which times it whole against ``hybridgen run``.

Run: .venv/bin/python tools/pyrender_reference.py SPEC.json [--hit-fraction]
     (SPEC: tools/label_configs.write_configs; --hit-fraction prints keypoint 0's share of pixels that hit a
     surface and stops)
"""
from __future__ import annotations

import argparse
import os
from pathlib import Path


def pyrender_script(spec_path: str, hit_fraction: bool = False) -> None:
    """The reference a user compares with: load the same mesh files with trimesh, render depth + segmentation
    (colour-coded ids, decoded) of the same poses with pyrender, write nothing. Runs as its own process."""
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    import json

    import numpy as np

    if not hasattr(np, "infty"):
        np.infty = np.inf  # pyrender 0.1.45 still uses the alias removed in NumPy 2
    import pyrender
    import trimesh

    spec = json.loads(Path(spec_path).read_text())
    scene = pyrender.Scene()
    seg = {}
    instance = 0
    for entry in spec["meshes"]:
        kwargs = {"file_type": "obj", "force": "scene"} if entry["path"].endswith(".obj") else {}
        loaded = trimesh.load(entry["path"], process=False, **kwargs)
        geometries = list(loaded.geometry.values()) if isinstance(loaded, trimesh.Scene) else [loaded]
        for geometry in geometries:
            instance += 1
            node = scene.add(pyrender.Mesh.from_trimesh(geometry), pose=np.asarray(entry["pose"]))
            seg[node] = [instance % 256, instance // 256, 0]
    K, (width, height) = np.asarray(spec["K"]), spec["resolution"]
    camera = scene.add(pyrender.IntrinsicsCamera(K[0, 0], K[1, 1], K[0, 2] + 0.5, K[1, 2] + 0.5,
                                                 znear=spec["clip"][0], zfar=spec["clip"][1]))
    renderer = pyrender.OffscreenRenderer(width, height)
    flip = np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV camera axes -> OpenGL camera axes
    for pose in spec["poses"]:
        scene.set_pose(camera, np.asarray(pose) @ flip)
        color, depth = renderer.render(scene, flags=pyrender.RenderFlags.SEG, seg_node_map=seg)
        ids = color[..., 0].astype(np.int32) + 256 * color[..., 1].astype(np.int32)
        assert depth.shape == ids.shape == (height, width)
        if hit_fraction:  # --hit-fraction: keypoint 0's share of pixels that hit a surface, then stop
            print(float(np.mean(depth > 0)))
            break
    renderer.delete()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", help="JSON spec written by tools/label_configs.write_configs")
    parser.add_argument("--hit-fraction", action="store_true", help="print keypoint 0's share of pixels that hit "
                        "a surface, then stop")
    args = parser.parse_args()
    pyrender_script(args.spec, hit_fraction=args.hit_fraction)
