"""Measure Blender 4.2's Principled sheen lobe in Cycles: the value "BSDF x cosine" of a sheen-only Principled
BSDF for many (view cosine, Sheen Roughness, light direction) triples, and its directional albedo.

Runs inside the ``bpy`` venv (pip's ``bpy`` 4.2, Blender as a Python module)::

    .venv-bpy/bin/python tools/principled_sheen_cycles.py OUT.npz [--lights 256] [--random 200]

The scene: one flat quad per (mu, roughness) sample, every quad of one mesh, each tilted about the world X axis
so that an orthographic camera looking down -Z sees it at view cosine mu, and shaped so that its image is one
3 x 3-pixel cell of the image (a long quad for grazing views). Each quad's material is a Principled BSDF with
Base Color black, Specular IOR Level 0 (so Cycles makes neither a diffuse nor a specular closure), Sheen
Weight 1, Sheen Tint white and the sample's Sheen Roughness. The quads are visible to camera rays only (no
shadows, no reflections of each other), bounces 0, one-pixel box filter, no denoising, no light threshold.

- Lobe renders (``--lights`` of them): a sun of strength 1 W/m^2 and angle 0 (a delta light) from one direction
  of a Fibonacci sphere, black world: the centre pixel of a cell is exactly the lobe's BSDF x cosine for that
  light direction (Cycles' sheen closure is deterministic; a delta light has no MIS).
- Furnace render: world radiance 1 with light sampling of the world off (``sampling_method = 'NONE'``), no sun:
  BSDF sampling alone, whose every sample weighs the lobe's albedo exactly.

Written (NumPy ``.npz``): ``mu`` (N,), ``rough`` (N,) per quad; ``directions`` (L, 3) the world directions
towards the sun (tools/principled_tables.sheen_frame_lights turns them into each quad's sheen frame: x the
view direction projected on the surface, z the normal); ``value`` (L, N) the pixel values (mean of R, G, B);
``albedo`` (N,) the furnace pixel values; ``role`` (N,) 0 for the lattice, 1 for the random held-out samples.
tools/principled_tables.py --sheen fits hybridgen's sheen tables to it.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from principled_tables import sheen_quad_frame  # noqa: E402  (tools/ is not a package in the bpy venv)

CELL = 3  # pixels per quad cell side (the centre pixel lies wholly inside the quad)
PIXEL = 0.01  # metres per pixel


def samples(mu_nodes: int, rough_nodes: int, random_count: int,
            seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mu, roughness, role) of the quads: a lattice, mu = i / (mu_nodes - 1) x roughness = j / (rough_nodes - 1),
    but mu 0 and 1 (not visible; no sheen frame) measured half a step inside, then ``random_count`` held-out
    random ones."""
    step = 1.0 / (mu_nodes - 1)
    mus = np.concatenate([[step / 2], np.arange(1, mu_nodes - 1) * step, [1.0 - step / 2]])
    mu, rough = np.meshgrid(mus, np.arange(rough_nodes) / (rough_nodes - 1), indexing="ij")
    rng = np.random.default_rng(seed)
    extra_mu = rng.uniform(0.04, 0.97, random_count)
    extra_rough = rng.uniform(0.0, 1.0, random_count)
    role = np.concatenate([np.zeros(mu.size), np.ones(random_count)])
    return np.concatenate([mu.ravel(), extra_mu]), np.concatenate([rough.ravel(), extra_rough]), role


def fibonacci_sphere(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere."""
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    phi = math.pi * (1.0 + 5.0 ** 0.5) * i
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def build(mu: np.ndarray, rough: np.ndarray) -> tuple[object, int]:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    cells = int(math.ceil(math.sqrt(len(mu))))
    size = cells * CELL * PIXEL
    side = CELL * PIXEL
    frames = sheen_quad_frame(mu)
    normal, tangent = frames[:, 2], frames[:, 0]
    vertices, faces = [], []
    for k in range(len(mu)):
        cx = (k % cells + 0.5) * side - size / 2
        cy = size / 2 - (k // cells + 0.5) * side
        along = tangent[k] * (side / mu[k] / 2)  # its image is side long along y
        across = np.array([side / 2, 0.0, 0.0])
        centre = np.array([cx, cy, 0.0])
        corners = [centre - across - along, centre + across - along, centre + across + along,
                   centre - across + along]
        base = len(vertices)
        vertices += [tuple(c) for c in corners]
        face = [base, base + 1, base + 2, base + 3]
        first = np.cross(corners[1] - corners[0], corners[2] - corners[0])
        faces.append(face if first @ normal[k] > 0 else face[::-1])
    mesh = bpy.data.meshes.new("quads")
    mesh.from_pydata(vertices, [], faces)
    materials = {}
    for k, r in enumerate(rough):
        key = round(float(r), 7)
        if key not in materials:
            material = bpy.data.materials.new(f"sheen_{len(materials)}")
            material.use_nodes = True
            principled = material.node_tree.nodes["Principled BSDF"]
            principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
            principled.inputs["Specular IOR Level"].default_value = 0.0
            principled.inputs["Sheen Weight"].default_value = 1.0
            principled.inputs["Sheen Roughness"].default_value = float(r)
            principled.inputs["Sheen Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
            mesh.materials.append(material)
            materials[key] = len(materials)
        mesh.polygons[k].material_index = materials[key]
    obj = bpy.data.objects.new("quads", mesh)
    scene.collection.objects.link(obj)
    obj.visible_diffuse = obj.visible_glossy = obj.visible_transmission = False
    obj.visible_volume_scatter = obj.visible_shadow = False

    sun = bpy.data.lights.new("sun", "SUN")
    sun.angle, sun.energy = 0.0, 1.0
    sun_object = bpy.data.objects.new("sun", sun)
    scene.collection.objects.link(sun_object)

    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    scene.world = world
    world.cycles.sampling_method = "NONE"  # the furnace: BSDF sampling alone

    camera_data = bpy.data.cameras.new("camera")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = size
    camera_data.clip_start, camera_data.clip_end = 0.1, 1000.0
    camera = bpy.data.objects.new("camera", camera_data)
    camera.location = (0.0, 0.0, 100.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = 1
    cycles.use_adaptive_sampling = cycles.use_denoising = cycles.use_light_tree = False
    cycles.max_bounces = cycles.diffuse_bounces = cycles.glossy_bounces = cycles.transmission_bounces = 0
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0  # (its default 0.01 drops or boosts dim light samples at random)
    cycles.pixel_filter_type, cycles.filter_width = "BOX", 1.0
    scene.render.resolution_x = scene.render.resolution_y = cells * CELL
    scene.render.resolution_percentage = 100
    scene.render.use_persistent_data = True
    scene.view_settings.view_transform, scene.view_settings.look = "Standard", "None"
    scene.render.image_settings.file_format, scene.render.image_settings.color_depth = "OPEN_EXR", "32"
    return scene, cells


def render_cells(scene: object, cells: int, count: int, workdir: str) -> np.ndarray:
    """The centre pixel (mean of R, G, B) of each quad's cell in a fresh render."""
    import bpy

    path = os.path.join(workdir, "render.exr")
    bpy.ops.render.render(write_still=False)
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    image = bpy.data.images.load(path)
    width = height = cells * CELL
    pixels = np.array(image.pixels[:], np.float64).reshape(height, width, 4)[::-1, :, :3]  # top row first
    bpy.data.images.remove(image)
    k = np.arange(count)
    rows, columns = (k // cells) * CELL + CELL // 2, (k % cells) * CELL + CELL // 2
    return pixels[rows, columns].mean(axis=1)


def main() -> None:
    import bpy
    import mathutils

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--lights", type=int, default=256)
    parser.add_argument("--random", type=int, default=200)
    parser.add_argument("--mu-nodes", type=int, default=129)
    parser.add_argument("--rough-nodes", type=int, default=129)
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else None)
    mu, rough, role = samples(args.mu_nodes, args.rough_nodes, args.random)
    scene, cells = build(mu, rough)
    sun = bpy.data.objects["sun"]
    background = scene.world.node_tree.nodes["Background"]
    directions = fibonacci_sphere(args.lights)
    values = []
    with tempfile.TemporaryDirectory() as workdir:
        background.inputs["Strength"].default_value = 0.0
        for index, d in enumerate(directions):
            # a sun shines along its local -Z: its +Z axis is the direction towards the light
            sun.matrix_world = mathutils.Vector(d.tolist()).to_track_quat("Z", "Y").to_matrix().to_4x4()
            values.append(render_cells(scene, cells, len(mu), workdir))
            print(f"light {index + 1}/{len(directions)}", file=sys.stderr, flush=True)
        sun.hide_render = True
        background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        background.inputs["Strength"].default_value = 1.0
        scene.cycles.samples = 16
        albedo = render_cells(scene, cells, len(mu), workdir)
    np.savez_compressed(args.out, mu=mu.astype(np.float32), rough=rough.astype(np.float32),
                        directions=directions.astype(np.float32), value=np.array(values, np.float32),
                        albedo=albedo.astype(np.float32), role=role.astype(np.int8),
                        blender=np.array(bpy.app.version_string))
    print(f"wrote {args.out}: {len(mu)} quads x {len(directions)} lights", file=sys.stderr)


if __name__ == "__main__":
    main()
