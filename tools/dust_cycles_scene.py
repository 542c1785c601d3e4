"""The Blender side of tools/dust_vs_cycles.py: builds its scene in bpy 4.2, puts dust on the materials with the
real BlenderProc's ``add_dust`` (``blenderproc.python.material.Dust``, imported from the extracted source that
tools/blenderproc_reference.py puts on PYTHONPATH; nothing of it is stored here) and renders a multilayer EXR.

    PYTHONPATH=<BlenderProc source> USE_EXTERNAL_BPY_MODULE=1 .venv-blenderproc/bin/python \\
        tools/dust_cycles_scene.py SCENE.npz SPEC.json OUT.exr

SPEC.json: ``mode`` ``look`` (the scene under its sun and world at ``spp`` with ``bounces`` in every lobe, no
clamp, no denoising, one-pixel box filter) or ``weight`` (each material's Principled BSDF replaced by black
emission and the dust group's BSDF by white emission, one sample at the pixel centre: the Combined pass is the
dust weight itself, with the UV, Normal and Position passes of that same sample); ``objects`` (name,
``base_color``, ``roughness``, ``specular``, ``dust``: [[strength, texture_scale], ...]), ``sun``
(``local2world``, ``energy``), ``world`` (RGB), ``camera`` (Blender ``matrix_world``, ``lens`` mm on a 36 mm
wide sensor), ``resolution``. SCENE.npz: per object ``<name>.vertices``, ``.faces``, ``.uvs``, ``.normals``
(world coordinates; smooth shading with these custom normals).
"""
from __future__ import annotations

import json
import os
import sys

import bpy
import mathutils
import numpy as np


def add_mesh(name: str, data: np.lib.npyio.NpzFile) -> bpy.types.Object:
    """Object ``name`` of ``data`` (``.vertices``, ``.faces``, ``.normals`` and, if there, per-vertex ``.uvs``),
    smooth with the normals as custom normals, linked to the scene."""
    vertices, faces = data[f"{name}.vertices"], data[f"{name}.faces"]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], faces.tolist())
    if f"{name}.uvs" in data:
        uv_layer = mesh.uv_layers.new(name="UVMap")
        uvs = data[f"{name}.uvs"]
        for loop in mesh.loops:
            uv_layer.data[loop.index].uv = uvs[loop.vertex_index].tolist()
    mesh.shade_smooth()
    mesh.normals_split_custom_set_from_vertices(data[f"{name}.normals"].tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _material(spec: dict, weight_mode: bool) -> bpy.types.Material:
    from blenderproc.python.material.Dust import add_dust
    from blenderproc.python.types.MaterialUtility import Material

    material = bpy.data.materials.new(spec["name"])
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*spec["base_color"], 1.0)
    bsdf.inputs["Roughness"].default_value = spec["roughness"]
    bsdf.inputs["Specular IOR Level"].default_value = spec["specular"]
    wrapped = Material(material)
    for strength, scale in spec["dust"]:
        add_dust(wrapped, strength=strength, texture_scale=scale)
    if weight_mode:
        _emissive(material.node_tree, bsdf, 0.0)
        for group in (n for n in material.node_tree.nodes if n.type == "GROUP"):
            inner = next(n for n in group.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
            _emissive(group.node_tree, inner, 1.0)
    return material


def _emissive(tree: bpy.types.NodeTree, bsdf: bpy.types.Node, value: float) -> None:
    """Replace ``bsdf``'s output links by an Emission shader of gray ``value``, strength 1."""
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (value, value, value, 1.0)
    emission.inputs["Strength"].default_value = 1.0
    for socket in [link.to_socket for link in bsdf.outputs["BSDF"].links]:
        tree.links.new(emission.outputs["Emission"], socket)  # replaces the link into that input


def start(argv: list[str]) -> tuple[np.lib.npyio.NpzFile, dict, str, bpy.types.Scene]:
    """The Blender sides' arguments ``SCENE.npz SPEC.json OUT.exr`` read (arrays, spec, output path), and Blender
    reset to an empty scene (returned)."""
    scene_path, spec_path, out = argv[1:4]
    with open(spec_path) as spec_file:
        spec = json.load(spec_file)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return np.load(scene_path), spec, out, bpy.context.scene


def add_camera(scene: bpy.types.Scene, camera_spec: dict) -> None:
    """The scene's camera: Blender ``matrix_world``, ``lens`` (mm) on a 36 mm wide sensor, clip start 1 cm."""
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit, camera_data.sensor_width = "HORIZONTAL", 36.0
    camera_data.lens = camera_spec["lens"]
    camera_data.clip_start = 0.01
    camera = bpy.data.objects.new("camera", camera_data)
    camera.matrix_world = mathutils.Matrix(camera_spec["matrix_world"])
    scene.collection.objects.link(camera)
    scene.camera = camera


def main() -> None:
    data, spec, out, scene = start(sys.argv)
    weight_mode = spec["mode"] == "weight"
    for entry in spec["objects"]:
        obj = add_mesh(entry["name"], data)
        obj.data.materials.append(_material(entry, weight_mode))
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*spec["world"], 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0 if weight_mode else 1.0
    scene.world = world
    if not weight_mode:
        sun = bpy.data.lights.new("sun", "SUN")
        sun.energy, sun.angle = spec["sun"]["energy"], 0.0
        sun_object = bpy.data.objects.new("sun", sun)
        sun_object.matrix_world = mathutils.Matrix(spec["sun"]["local2world"])
        scene.collection.objects.link(sun_object)
    add_camera(scene, spec["camera"])

    cycles = scene.cycles
    scene.render.engine, cycles.device = "CYCLES", "CPU"
    cycles.samples = 1 if weight_mode else spec["spp"]
    cycles.use_adaptive_sampling = cycles.use_denoising = cycles.use_light_tree = False
    bounces = spec.get("bounces", 3)
    cycles.max_bounces = cycles.diffuse_bounces = cycles.glossy_bounces = cycles.transmission_bounces = bounces
    cycles.sample_clamp_direct = cycles.sample_clamp_indirect = cycles.blur_glossy = 0.0
    cycles.caustics_reflective = cycles.caustics_refractive = True
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 0.01 if weight_mode else 1.0
    cycles.seed = spec.get("seed", 0)
    layer = scene.view_layers[0]
    layer.use_pass_uv = layer.use_pass_normal = layer.use_pass_position = weight_mode
    layer.use_pass_diffuse_color = not weight_mode
    render_exr(scene, spec["resolution"], out)


def render_pixel_centres(scene: bpy.types.Scene, resolution: list[int], out: str) -> None:
    """Render ``scene`` in a black world on the CPU with one sample per pixel through a 0.01-pixel box filter, no
    adaptive sampling or denoising: each pixel's passes are Cycles' values at its centre (exact for passes that
    are no random estimate: normals, UVs, closure weights). Into the multilayer EXR ``out``."""
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    cycles = scene.cycles
    scene.render.engine, cycles.device = "CYCLES", "CPU"
    cycles.samples = 1
    cycles.use_adaptive_sampling = cycles.use_denoising = False
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 0.01
    render_exr(scene, resolution, out)


def render_exr(scene: bpy.types.Scene, resolution: list[int], out: str) -> None:
    """Render ``scene`` at ``resolution`` (width, height) into the multilayer float32 EXR ``out``."""
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # bpy 4.2 with BlenderProc imported can crash while the interpreter shuts down
