"""Deterministic scenes of the label benchmarks (tools/bench_labels.py, bench_writer.py, bench_startup.py):
meshes in world coordinates, orbit camera poses, intrinsics (metres, radians, pixels).

The real meshes come from the ``pybullet`` wheel (its ``pybullet_data`` folder): ``pip install pybullet``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

import hybridgen as hg

RESOLUTIONS = {"640x480": (640, 480), "1280x720": (1280, 720)}


def pybullet_data_dir() -> Path:
    """The folder of real meshes the ``pybullet`` wheel ships (``pip install pybullet``)."""
    try:
        import pybullet_data
    except ImportError:
        raise SystemExit("the benchmarks' real meshes come with pybullet: .venv/bin/pip install pybullet") from None
    return Path(pybullet_data.getDataPath())


def objects_50(seed: int = 0) -> hg.Scene:
    """50 objects (136,058 triangles) on a floor: real meshes from pybullet_data (duck, bunny, teddy,
    soccer ball, ...) mixed with primitives and the repository's knot, at random poses."""
    rng = np.random.default_rng(seed)
    data = pybullet_data_dir()
    repo = Path(__file__).resolve().parents[1]
    files = [data / "duck.obj", data / "bunny.obj", data / "teddy2_VHACD_CHs.obj", data / "soccerball.obj",
             data / "sphere_smooth.obj", repo / "configs/assets/knot.obj"]
    scene = hg.Scene()
    scene.add(hg.make_primitive("plane", 12.0, name="floor", category_id=1))
    shapes = ["sphere", "torus", "cylinder", "cone", "cube"]
    while len(scene.objects) < 50:
        i = len(scene.objects)
        location = [*rng.uniform(-4, 4, 2), rng.uniform(0.3, 1.5)]
        rotation = rng.uniform(-np.pi, np.pi, 3)
        if i % 2:
            path = files[(i // 2) % len(files)]
            parts = hg.load_objects(path, name=f"obj{i}", category_id=2 + i % 5)
            mesh = parts[0]
            size = float(np.ptp(mesh.vertices, axis=0).max())
            mesh.local2world = hg.object_pose(location, rotation, rng.uniform(0.5, 1.0) / size)
            scene.add(mesh)
        else:
            pose = hg.object_pose(location, rotation, rng.uniform(0.4, 0.9))
            scene.add(hg.make_primitive(shapes[(i // 2) % len(shapes)], 1.0, name=f"obj{i}", category_id=2 + i % 5,
                                        local2world=pose))
    return scene


def monastery() -> hg.Scene:
    """pybullet_data's samurai_monastry.obj: a real 124,789-triangle scene mesh (81 parts, nearly all open).

    The file is +Y up (pybullet's samurai.urdf turns it by 90 degrees about X, as ``up_axis="Y"`` does)."""
    scene = hg.Scene()
    for obj in hg.load_objects(pybullet_data_dir() / "samurai_monastry.obj", name="monastery", category_id=1,
                               up_axis="Y"):
        scene.add(obj)
    return scene


def subdivided_real_mesh(levels: int = 3) -> hg.Scene:
    """A real mesh made dense: pybullet_data's mini_cheetah body (22,384 triangles, closed, smooth normals)
    split ``levels`` times into 4 (3: 1,432,576 triangles; same shape, midpoint normals), on a floor."""
    import trimesh

    body = hg.load_objects(pybullet_data_dir() / "mini_cheetah/meshes/mini_body.obj", name="mini_body")[0]
    vertices, faces, normals = body.vertices, body.faces, body.vertex_normals
    for _ in range(levels):
        vertices, faces, attributes = trimesh.remesh.subdivide(vertices, faces, vertex_attributes={"normal": normals})
        normals = attributes["normal"] / np.linalg.norm(attributes["normal"], axis=1, keepdims=True)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    scale = 3.0 / float((high - low).max())  # about 3 m long, resting on the floor
    scene = hg.Scene()
    scene.add(hg.MeshObject("mini_body_dense", vertices, faces, vertex_normals=normals, category_id=2,
                            local2world=hg.object_pose([0, 0, -low[2] * scale], [0, 0, 0.4], scale)))
    scene.add(hg.make_primitive("plane", 12.0, name="floor", category_id=1))
    return scene


def icosphere_dense() -> hg.Scene:
    """One 1,310,720-triangle mesh (an icosphere of 8 subdivisions, smooth normals) on a floor."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=8, radius=1.5)
    scene = hg.Scene()
    scene.add(hg.MeshObject("dense", sphere.vertices, sphere.faces, vertex_normals=sphere.vertices / 1.5,
                            category_id=2, local2world=hg.object_pose([0, 0, 1.5])))
    scene.add(hg.make_primitive("plane", 12.0, name="floor", category_id=1))
    return scene


SCENES = {"50 objects": objects_50, "monastery (real)": monastery, "1.4M real, subdiv.": subdivided_real_mesh}
"""The default benchmark scenes."""
EXTRA_SCENES = {"1.3M icosphere": icosphere_dense}
"""Further scenes, chosen by name (``--scenes``)."""
ALL_SCENES = SCENES | EXTRA_SCENES


def orbit_poses(scene: hg.Scene, count: int, seed: int = 1) -> list[np.ndarray]:
    """``count`` look-at poses around the bounding box of the scene's objects (the floor left out), outside
    it, looking at its centre."""
    framed = [o for o in scene.objects if o.name != "floor"] or scene.objects
    points = np.concatenate([o.world_vertices() for o in framed])
    low, high = points.min(axis=0), points.max(axis=0)
    centre = (low + high) / 2
    radius = 0.6 * float(np.linalg.norm(high - low))
    rng = np.random.default_rng(seed)
    poses = []
    for i in range(count):
        azimuth = 2 * np.pi * i / count + rng.uniform(-0.2, 0.2)
        location = centre + radius * np.array([np.cos(azimuth), np.sin(azimuth), rng.uniform(0.3, 0.6)])
        poses.append(hg.look_at(location, centre))
    return poses


def intrinsics(width: int, height: int, clip_end: float = 1000.0) -> hg.Intrinsics:
    """A 60-degree horizontal field of view with a centred principal point."""
    return hg.Intrinsics.from_fov(np.radians(60), width, height, clip_start=0.05, clip_end=clip_end)
