"""The Blender side of tools/bump_vs_cycles.py: Cycles' bumped normals of a plane whose displacement the real
BlenderProc's ``set_displacement_from_principled_shader_value`` links from its base-color image, in bpy 4.2.

    PYTHONPATH=<BlenderProc source> USE_EXTERNAL_BPY_MODULE=1 .venv-blenderproc/bin/python \\
        tools/bump_cycles.py SCENE.npz SPEC.json OUT.exr

SPEC.json: ``texture`` (an sRGB color image, linked through an Image Texture node to Base Color, as Blender's OBJ
importer links ``map_Kd``), ``factor`` (BlenderProc's ``multiply_factor``), ``camera`` (Blender ``matrix_world``,
``lens`` mm on a 36 mm wide sensor), ``resolution``. SCENE.npz: ``plane.vertices``, ``.faces``, ``.normals``,
``.uvs`` (world coordinates). BlenderProc's call itself (imported from the extracted source that
tools/blenderproc_reference.py puts on PYTHONPATH; nothing of it is stored here) builds the node setup, and the
material keeps Blender's default displacement method (Bump Only). One sample per pixel through a 0.01-pixel box
filter: the Normal pass is Cycles' bumped shading normal at each pixel centre (no estimate: one sample is exact);
the UV pass goes with it. No lights: the normals do not depend on them.
"""
from __future__ import annotations

import os
import sys

import bpy
from dust_cycles_scene import add_camera, add_mesh, render_pixel_centres, start  # tools/ is first on sys.path


def _material(texture: str, factor: float) -> bpy.types.Material:
    from blenderproc.python.types.MaterialUtility import Material

    material = bpy.data.materials.new("bumped")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    image = nodes.new("ShaderNodeTexImage")
    image.image = bpy.data.images.load(texture)
    material.node_tree.links.new(image.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    Material(material).set_displacement_from_principled_shader_value("Base Color", multiply_factor=factor)
    return material


def main() -> None:
    data, spec, out, scene = start(sys.argv)
    add_mesh("plane", data).data.materials.append(_material(spec["texture"], spec["factor"]))
    add_camera(scene, spec["camera"])
    layer = scene.view_layers[0]
    layer.use_pass_normal = layer.use_pass_uv = True
    render_pixel_centres(scene, spec["resolution"], out)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)  # bpy 4.2 with BlenderProc imported can crash while the interpreter shuts down
