"""Write a small .blend test scene with Blender's ``bpy`` (run with the bpy venv's Python, e.g. ``.venv-bpy``).

    .venv-bpy/bin/python tools/make_blend_fixture.py OUT.blend

The scene (metres, world Z up): a 2 m cube ``Box`` at (0, 0, 1) turned 0.3 rad about Z, with the material
``Painted`` (Principled BSDF: base color image ``checker.png`` - 4 x 4 texels, written next to OUT -, roughness
0.35, metallic 0.2, Coat Weight 0.8, Coat Roughness 0.2, the same image as a Non-Color coat normal map through a
Normal Map node) and custom properties ``category_id`` 7 and ``label`` "box"; a 10 m plane ``Ground``
with ``Floor`` (base color (0.2, 0.4, 0.6), roughness 0.8, Specular Tint (1, 0.9, 0.8), Sheen Roughness 0.2
without sheen) and ``category_id`` 1, scaled 1.5 in Blender;
a point light ``Lamp`` of 500 W at (2, -2, 4), color (1, 0.9, 0.8); an empty ``Target`` at (0, 0, 1);
the world background (0.1, 0.2, 0.3) at strength 0.5.
"""
from __future__ import annotations

import sys
from pathlib import Path

import bpy  # type: ignore[import-not-found]
import numpy as np

CHECKER = np.array([[255, 0], [0, 255]], np.uint8).repeat(2, 0).repeat(2, 1)


def _principled(name: str) -> tuple:
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    node = material.node_tree.nodes["Principled BSDF"]
    return material, node


def main(out: Path) -> None:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    image_path = out.with_name("checker.png")
    image = bpy.data.images.new("checker", 4, 4)
    pixels = np.zeros((4, 4, 4), np.float32)
    pixels[..., :3] = (CHECKER / 255.0)[..., None]
    pixels[..., 3] = 1.0
    image.pixels.foreach_set(pixels.ravel())
    image.filepath_raw = str(image_path)
    image.file_format = "PNG"
    image.save()

    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0), rotation=(0.0, 0.0, 0.3))
    box = bpy.context.active_object
    box.name = "Box"
    box["category_id"] = 7
    box["label"] = "box"
    painted, node = _principled("Painted")
    node.inputs["Roughness"].default_value = 0.35
    node.inputs["Metallic"].default_value = 0.2
    texture = painted.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(str(image_path))
    painted.node_tree.links.new(texture.outputs["Color"], node.inputs["Base Color"])
    node.inputs["Coat Weight"].default_value = 0.8
    node.inputs["Coat Roughness"].default_value = 0.2
    coat_map = painted.node_tree.nodes.new("ShaderNodeTexImage")
    coat_map.image = bpy.data.images.load(str(image_path))
    coat_map.image.colorspace_settings.name = "Non-Color"
    normal_map = painted.node_tree.nodes.new("ShaderNodeNormalMap")
    painted.node_tree.links.new(coat_map.outputs["Color"], normal_map.inputs["Color"])
    painted.node_tree.links.new(normal_map.outputs["Normal"], node.inputs["Coat Normal"])
    box.data.materials.append(painted)

    bpy.ops.mesh.primitive_plane_add(size=10.0)
    ground = bpy.context.active_object
    ground.name = "Ground"
    ground.scale = (1.5, 1.5, 1.0)
    ground["category_id"] = 1
    floor, node = _principled("Floor")
    node.inputs["Base Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    node.inputs["Roughness"].default_value = 0.8
    node.inputs["Specular Tint"].default_value = (1.0, 0.9, 0.8, 1.0)
    node.inputs["Sheen Roughness"].default_value = 0.2  # no effect: Sheen Weight stays 0
    ground.data.materials.append(floor)

    lamp = bpy.data.lights.new("Lamp", type="POINT")
    lamp.energy = 500.0
    lamp.color = (1.0, 0.9, 0.8)
    lamp_object = bpy.data.objects.new("Lamp", lamp)
    lamp_object.location = (2.0, -2.0, 4.0)
    scene.collection.objects.link(lamp_object)

    target = bpy.data.objects.new("Target", None)
    target.location = (0.0, 0.0, 1.0)
    scene.collection.objects.link(target)

    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.1, 0.2, 0.3, 1.0)
    background.inputs["Strength"].default_value = 0.5
    scene.world = world
    bpy.ops.wm.save_as_mainfile(filepath=str(out))


if __name__ == "__main__":
    main(Path(sys.argv[1]).resolve())
