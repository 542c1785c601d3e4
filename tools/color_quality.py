"""The four scenes of the color quality benchmark (tools/bench_color_quality.py), one keypoint each, built from
pybullet_data meshes, primitives and generated textures. Units: metres, radians; sizes in pixels.

- ``tabletop``: textured duck, bunny, football and a glossy (roughness 0.2) mug-like cylinder on a floor, one
  point light (the issue's scene);
- ``materials``: glossy, metallic, glass and emissive spheres on a floor, one point light;
- ``window_room``: a closed room with a window, a checker-textured floor and wall texture, lit by a sun and
  a sky (world color) through the window only;
- ``hdri_tabletop``: objects on a floor under a generated HDRI (sky gradient with a small, bright sun).

The other color tools (tools/default_color_process.py, tools/reference_noise.py, tools/color_regions.py,
tools/color_decompose.py, tools/bench_denoise_guides.py) render these same scenes.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np


# ------------------------------------------------------------------------------------------ scenes
def _camera(scene: Any, width: int, height: int, location: list[float], target: list[float], fov: float) -> None:
    import hybridgen as hg

    scene.camera.intrinsics = hg.Intrinsics.from_fov(fov, width, height, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at(location, target))


def _floor(size: float = 6.0, albedo: float = 0.6) -> Any:
    import hybridgen as hg

    floor = hg.make_primitive("plane", size, name="floor", category_id=1, color=(albedo, albedo, albedo))
    floor.material.specular = 0.0
    return floor


def _pybullet_mesh(file: str, name: str, category_id: int, size: float, xy: tuple[float, float],
                   yaw: float = 0.0) -> list[Any]:
    """A pybullet_data mesh scaled to ``size`` m (largest extent), turned by ``yaw`` about +Z and standing
    on the floor at ``xy``."""
    import pybullet_data

    import hybridgen as hg

    objects = hg.load_objects(Path(pybullet_data.getDataPath()) / file, name=name, category_id=category_id)
    vertices = np.concatenate([obj.world_vertices() for obj in objects])
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    centre = np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]])
    move = hg.object_pose([xy[0], xy[1], 0.0], [0.0, 0.0, yaw]) @ np.diag([size / np.max(high - low)] * 3 + [1.0])
    move = move @ hg.object_pose((-centre).tolist())
    for obj in objects:
        obj.local2world = move @ obj.local2world
    return objects


def checker(size: int = 256, squares: int = 8, a: tuple[int, ...] = (200, 190, 170),
            b: tuple[int, ...] = (70, 60, 50)) -> np.ndarray:
    """An sRGB uint8 checkerboard texture (size x size x 3)."""
    cells = (np.indices((size, size)) * squares // size).sum(axis=0) % 2
    return np.where(cells[..., None] == 0, np.array(a, np.uint8), np.array(b, np.uint8)).astype(np.uint8)


def planar_uvs(obj: Any, repeat: float = 1.0) -> None:
    """UVs from the object's local x/y (a plane primitive spans -size/2..size/2)."""
    xy = obj.vertices[:, :2]
    span = np.ptp(xy, axis=0)
    obj.uvs = ((xy - xy.min(axis=0)) / np.where(span > 0, span, 1.0) * repeat).astype(np.float32)


def tabletop(width: int, height: int) -> Any:
    import hybridgen as hg

    scene = hg.Scene()
    scene.add(_floor())
    for obj in _pybullet_mesh("duck.obj", "duck", 2, 0.3, (-0.35, 0.1), 0.5):
        scene.add(obj)
    for obj in _pybullet_mesh("bunny.obj", "bunny", 3, 0.3, (0.3, 0.25)):
        obj.material.specular = 0.0
        scene.add(obj)
    for obj in _pybullet_mesh("soccerball.obj", "football", 4, 0.22, (0.35, -0.3)):
        scene.add(obj)
    mug = hg.make_primitive("cylinder", 0.22, name="mug", category_id=5, color=(0.75, 0.2, 0.15),
                            local2world=hg.object_pose([-0.05, -0.35, 0.11]))
    mug.material.roughness, mug.material.specular = 0.2, 0.5
    scene.add(mug)
    scene.add_light(hg.Light("lamp", "POINT", energy=150.0, local2world=hg.object_pose([0.6, -0.8, 1.6])))
    _camera(scene, width, height, [1.1, -1.3, 0.9], [0.0, 0.0, 0.1], 0.9)
    return scene


def materials(width: int, height: int) -> Any:
    import hybridgen as hg

    scene = hg.Scene()
    scene.add(_floor())
    spheres = [("glossy", (0.1, 0.3, 0.8), dict(roughness=0.2, specular=0.5)),
               ("metal", (0.9, 0.7, 0.4), dict(metallic=1.0, roughness=0.1)),
               ("glass", (1.0, 1.0, 1.0), dict(transmission=1.0, roughness=0.0, ior=1.5)),
               ("emitter", (1.0, 0.6, 0.3), dict(emission=(1.0, 0.6, 0.3), emission_strength=4.0, specular=0.0))]
    for index, (name, color, values) in enumerate(spheres):
        ball = hg.make_primitive("sphere", 0.3, name=name, category_id=index + 2, color=color,
                                 local2world=hg.object_pose([-0.55 + 0.37 * index, 0.0, 0.15]))
        for key, value in values.items():
            setattr(ball.material, key, value)
        scene.add(ball)
    scene.add_light(hg.Light("lamp", "POINT", energy=120.0, local2world=hg.object_pose([0.4, -0.9, 1.4])))
    _camera(scene, width, height, [0.2, -1.6, 0.7], [0.0, 0.0, 0.12], 0.8)
    return scene


def window_room(width: int, height: int) -> Any:
    """A 4 x 4 x 2.6 m room; the +y wall has a 1.2 x 1.0 m window; sun and sky shine in through it."""
    import hybridgen as hg

    scene = hg.Scene()
    floor = _floor(4.0, 0.8)
    floor.material.base_color_texture = checker()
    planar_uvs(floor, repeat=2.0)
    scene.add(floor)
    half, top = 2.0, 2.6
    walls = [  # (name, size x, size y, pose): planes are z-up squares scaled into rectangles
        ("ceiling", 4.0, 4.0, hg.object_pose([0, 0, top], [math.pi, 0, 0])),
        ("wall_west", 4.0, top, hg.object_pose([-half, 0, top / 2], [0, math.pi / 2, 0])),
        ("wall_east", 4.0, top, hg.object_pose([half, 0, top / 2], [0, -math.pi / 2, 0])),
        ("wall_south", 4.0, top, hg.object_pose([0, -half, top / 2], [-math.pi / 2, 0, 0])),
        # the window wall (y = +2) around a hole x in [-0.6, 0.6], z in [0.9, 1.9]
        ("window_left", 1.4, top, hg.object_pose([-1.3, half, top / 2], [math.pi / 2, 0, 0])),
        ("window_right", 1.4, top, hg.object_pose([1.3, half, top / 2], [math.pi / 2, 0, 0])),
        ("window_below", 1.2, 0.9, hg.object_pose([0, half, 0.45], [math.pi / 2, 0, 0])),
        ("window_above", 1.2, 0.7, hg.object_pose([0, half, 2.25], [math.pi / 2, 0, 0])),
    ]
    for index, (name, sx, sy, pose) in enumerate(walls):
        wall = hg.make_primitive("plane", 1.0, name=name, category_id=10 + index, color=(0.75, 0.72, 0.68),
                                 local2world=pose @ np.diag([sx, sy, 1.0, 1.0]))
        wall.material.specular = 0.0
        if name == "wall_west":
            wall.material.base_color_texture = checker(128, 4, (180, 60, 50), (230, 220, 200))
            planar_uvs(wall)
        scene.add(wall)
    table = hg.make_primitive("cube", 0.6, name="table", category_id=30, color=(0.5, 0.35, 0.2),
                              local2world=hg.object_pose([0.3, 0.4, 0.3]))
    table.material.roughness = 0.3
    scene.add(table)
    scene.world.color, scene.world.strength = (0.45, 0.6, 0.9), 1.0
    # sun from outside the window (+y), 35 degrees above the horizon, shining into the room along its -z
    scene.add_light(hg.Light("sun", "SUN", energy=4.0, local2world=hg.object_pose([0, 5, 4],
                                                                                 [-math.radians(55), 0, 0])))
    _camera(scene, width, height, [-1.5, -1.6, 1.5], [0.4, 1.0, 0.6], 1.3)
    return scene


def sky_hdri(path: Path, width: int = 256) -> Path:
    """An equirectangular float32 RGB EXR: a blue-to-white sky over a dark ground and a small sun, written
    with Mitsuba's Bitmap."""
    import mitsuba as mi

    height = width // 2
    theta = (np.arange(height) + 0.5) / height * math.pi  # 0 = zenith
    phi = (np.arange(width) + 0.5) / width * 2 * math.pi
    up = np.cos(theta)[:, None, None]
    sky = np.where(up > 0, 0.3 + 0.7 * np.array([0.4, 0.6, 1.0]) * np.maximum(up, 0.0) ** 0.4,
                   np.array([0.15, 0.13, 0.1]))
    image = np.broadcast_to(sky, (height, width, 3)).copy()
    sun_theta, sun_phi = math.radians(50), math.radians(120)
    d = np.stack([np.sin(theta)[:, None] * np.cos(phi)[None], np.sin(theta)[:, None] * np.sin(phi)[None],
                  np.broadcast_to(np.cos(theta)[:, None], (height, width))], axis=-1)
    s = np.array([math.sin(sun_theta) * math.cos(sun_phi), math.sin(sun_theta) * math.sin(sun_phi),
                  math.cos(sun_theta)])
    image[(d @ s) > math.cos(math.radians(3.0))] = [400.0, 380.0, 340.0]
    mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(path))
    return path


def hdri_tabletop(width: int, height: int, workdir: Path) -> Any:
    scene = tabletop(width, height)
    scene.lights.clear()
    scene.world.hdri_path = str(sky_hdri(workdir / "sky.exr"))
    scene.world.strength, scene.world.hdri_rotation = 1.0, 0.3
    return scene


SCENES = ("tabletop", "materials", "window_room", "hdri_tabletop")


def build(name: str, width: int, height: int, workdir: Path) -> Any:
    """Scene ``name`` (one of :data:`SCENES`) at ``width`` x ``height`` px; generated inputs go to ``workdir``."""
    if name == "hdri_tabletop":
        return hdri_tabletop(width, height, workdir)
    return {"tabletop": tabletop, "materials": materials, "window_room": window_room}[name](width, height)

