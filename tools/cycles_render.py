"""Renders a scene exported by bench_color.py with Blender Cycles (bpy from PyPI) and prints seconds per
keypoint as JSON. Runs inside its own virtual environment (bpy needs Python 3.11 and numpy < 2).

    .venv-bpy/bin/python tools/cycles_render.py SCENE.npz
"""
from __future__ import annotations

import json
import sys
import time

import bpy
import numpy as np


def main(path: str) -> None:
    data = np.load(path, allow_pickle=True)
    meta = json.loads(str(data["meta"]))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for index, obj in enumerate(meta["objects"]):
        vertices, faces = data[f"v{index}"], data[f"f{index}"]
        mesh = bpy.data.meshes.new(obj["name"])
        mesh.from_pydata(vertices.tolist(), [], faces.tolist())
        mesh.update()
        if obj["smooth"]:
            mesh.shade_smooth()
        material = bpy.data.materials.new(obj["name"])
        material.use_nodes = True
        bsdf = material.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (*obj["color"][:3], 1.0)
        bsdf.inputs["Roughness"].default_value = obj["roughness"]
        if obj["emission"] > 0:
            bsdf.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1.0)
            bsdf.inputs["Emission Strength"].default_value = obj["emission"]
        mesh.materials.append(material)
        scene.collection.objects.link(bpy.data.objects.new(obj["name"], mesh))
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*meta["world"], 1.0)
    scene.world = world
    width, height = meta["resolution"]
    K = np.array(meta["K"])
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit = "HORIZONTAL"
    camera_data.sensor_width = 36.0
    camera_data.lens = K[0, 0] * 36.0 / width
    camera_data.shift_x = -(K[0, 2] - (width - 1) / 2) / width
    camera_data.shift_y = (K[1, 2] - (height - 1) / 2) / width
    camera_data.clip_start, camera_data.clip_end = meta["clip"]
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = meta["spp"]
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.max_bounces = meta["max_bounces"]
    scene.cycles.diffuse_bounces = scene.cycles.glossy_bounces = meta["max_bounces"]
    scene.cycles.min_light_bounces = meta["min_bounces"]
    scene.render.threads_mode = "FIXED"
    scene.render.threads = meta["threads"]
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.filepath = meta["output"]
    times = []
    for pose in data["poses"]:
        blender_pose = pose @ np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV -> Blender camera axes
        camera.matrix_world = [list(row) for row in blender_pose]
        start = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        times.append(time.perf_counter() - start)
    print(json.dumps({"seconds": times, "blender": bpy.app.version_string}))


if __name__ == "__main__":
    main(sys.argv[1])
