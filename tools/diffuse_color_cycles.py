"""The Blender side of tools/diffuse_color_vs_cycles.py: Cycles' Diffuse Color pass (DiffCol) of Principled BSDF
materials in bpy 4.2, at pixel centres.

    .venv-blenderproc/bin/python tools/diffuse_color_cycles.py SCENE.npz SPEC.json OUT.exr

SPEC.json: ``objects`` (``name``, ``inputs``: {Principled BSDF input name: value}, colors as RGB lists),
``camera`` (Blender ``matrix_world``, ``lens`` mm on a 36 mm wide sensor), ``resolution``. SCENE.npz: per object
``<name>.vertices``, ``.faces``, ``.normals`` (world coordinates; smooth shading with these custom normals).
One sample per pixel through a 0.01-pixel box filter: each pixel's value is Cycles' DiffCol at the pixel centre
(the closure weights are no random estimate, so one sample is the exact value there). The EXR also holds the
Normal pass (the shading normal the closures saw). No lights: DiffCol does not depend on them.
"""
from __future__ import annotations

import os
import sys

import bpy
from dust_cycles_scene import add_camera, add_mesh, render_pixel_centres, start  # tools/ is first on sys.path


def _material(name: str, inputs: dict) -> bpy.types.Material:
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        socket = bsdf.inputs[key]
        socket.default_value = (*value, 1.0) if isinstance(value, list) and len(socket.default_value) == 4 else value
    return material


def main() -> None:
    data, spec, out, scene = start(sys.argv)
    for entry in spec["objects"]:
        add_mesh(entry["name"], data).data.materials.append(_material(entry["name"], entry["inputs"]))
    add_camera(scene, spec["camera"])
    layer = scene.view_layers[0]
    layer.use_pass_diffuse_color = layer.use_pass_normal = True
    render_pixel_centres(scene, spec["resolution"], out)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # bpy 4.2 can crash while the interpreter shuts down
