"""Child-process script: dump a .blend file's scene with Blender's ``bpy`` module (run by the bpy venv's Python).

    python blend_dump.py FILE.blend OUT_DIR OPTIONS_JSON

Writes ``OUT_DIR/scene.json`` (objects, lights, world) and ``OUT_DIR/arrays.npz``. It imports only ``bpy``
and NumPy (never hybridgen: the bpy wheel needs its own Python and NumPy < 2). Units are Blender's: metres,
world Z up; ``matrix_world`` is the object's 4x4 local-to-world matrix (row-major). Meshes are the
evaluated meshes (modifiers applied), triangulated, as one vertex per triangle corner (``<i>_positions``
(3T, 3) object-local, ``<i>_normals`` Blender's corner normals - flat or smooth as Blender shades -,
``<i>_uvs`` (3T, 2) of the active UV map, ``<i>_material`` (T,) slot index). Materials are read from a
Principled BSDF feeding the output (values and the image linked to an input - Normal and Coat Normal through a
Normal Map node -; the inputs ``OPTIONS["extra_inputs"]`` names, {key: socket name or node property}, under
``extra``); images packed in the file are written into OUT_DIR.

Subdivision Surface (and Multires) modifiers are evaluated at the level a render uses, not the viewport's:
their ``render_levels`` (``OPTIONS["render_levels"]`` replaces it: an int for every object, a dict by object
name, as BlenderProc's Rock Essentials loader sets it), capped by ``OPTIONS["simplify_subdivision_render"]`` (BlenderProc's renderer sets
the scene's Simplify to 3 by default; 0 means no cap).
"""
from __future__ import annotations

import json
import os
import re
import sys

import bpy  # type: ignore[import-not-found]
import numpy as np

_INPUTS = {"base_color": ("Base Color",), "roughness": ("Roughness",), "metallic": ("Metallic",),
           "specular": ("Specular IOR Level", "Specular"), "alpha": ("Alpha",), "ior": ("IOR",),
           "transmission": ("Transmission Weight", "Transmission"), "emission": ("Emission Color", "Emission"),
           "emission_strength": ("Emission Strength",)}


def _plain(value):
    """A custom property as JSON (IDProperty groups and arrays as dicts and lists; others as text)."""
    if hasattr(value, "to_dict"):
        return value.to_dict()
    if hasattr(value, "to_list"):
        return value.to_list()
    if isinstance(value, (bool, int, float, str)):
        return value
    return str(value)


def _custom_properties(block) -> dict:
    return {key: _plain(block[key]) for key in block.keys() if not key.startswith("_") and key != "cycles"}


def _image_path(image, out_dir: str) -> str | None:
    if image is None:
        return None
    if image.packed_file is not None:
        name = re.sub(r"[^\w.-]", "_", image.name) or "image"
        target = os.path.join(out_dir, f"packed_{name}.png")
        image.filepath_raw = target
        image.file_format = "PNG"
        image.save()
        return target
    return bpy.path.abspath(image.filepath, library=image.library) if image.filepath else None


def _linked_image(socket, out_dir: str) -> str | None:
    """The image of an Image Texture node linked (directly, or through one node such as a Normal Map) to
    ``socket``."""
    for link in socket.links:
        node = link.from_node
        if node.type == "TEX_IMAGE":
            return _image_path(node.image, out_dir)
        for inner in getattr(node, "inputs", []):
            for inner_link in inner.links:
                if inner_link.from_node.type == "TEX_IMAGE":
                    return _image_path(inner_link.from_node.image, out_dir)
    return None


def _material(material, out_dir: str, options: dict) -> dict:
    out = {"name": material.name if material else "default", "custom_properties": {}}
    if material is None:
        return out
    out["custom_properties"] = _custom_properties(material)
    out["diffuse_color"] = list(material.diffuse_color)
    principled = None
    if material.use_nodes and material.node_tree is not None:
        principled = next((n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if principled is None:
        return out
    values, textures = {}, {}
    for key, names in _INPUTS.items():
        socket = next((principled.inputs[n] for n in names if n in principled.inputs), None)
        if socket is None:
            continue
        value = socket.default_value
        values[key] = list(value) if hasattr(value, "__len__") else float(value)
        image = _linked_image(socket, out_dir)
        if image is not None:
            textures[key] = image
    for key, name in (("normal", "Normal"), ("coat_normal", "Coat Normal")):
        if name in principled.inputs:
            normal = _linked_image(principled.inputs[name], out_dir)
            if normal is not None:
                textures[key] = normal
    extra = {}
    for key, name in options.get("extra_inputs", {}).items():  # coat, sheen, ...: {key: socket name}
        if name in principled.inputs:
            value = principled.inputs[name].default_value
            extra[key] = list(value) if hasattr(value, "__len__") else float(value)
        elif hasattr(principled, name):  # a node property (subsurface_method)
            extra[key] = getattr(principled, name)
    out.update(principled=values, textures=textures, extra=extra)
    return out


def _mesh_arrays(obj, depsgraph, prefix: str, arrays: dict) -> dict:
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        tris = mesh.loop_triangles
        count = len(tris)
        loops = np.zeros(count * 3, np.int64)
        tris.foreach_get("loops", loops)
        verts = np.zeros(count * 3, np.int64)
        tris.foreach_get("vertices", verts)
        material = np.zeros(count, np.int64)
        tris.foreach_get("material_index", material)
        co = np.zeros(len(mesh.vertices) * 3, np.float64)
        mesh.vertices.foreach_get("co", co)
        normals = np.zeros(count * 9, np.float64)
        tris.foreach_get("split_normals", normals)
        arrays[f"{prefix}_positions"] = co.reshape(-1, 3)[verts]
        arrays[f"{prefix}_normals"] = normals.reshape(-1, 3)
        arrays[f"{prefix}_material"] = material
        uv_layer = mesh.uv_layers.active
        if uv_layer is not None:
            uv = np.zeros(len(mesh.loops) * 2, np.float64)
            uv_layer.data.foreach_get("uv", uv)
            arrays[f"{prefix}_uvs"] = uv.reshape(-1, 2)[loops]
        return {"triangles": count, "uvs": uv_layer is not None}
    finally:
        evaluated.to_mesh_clear()


def _light(obj) -> dict:
    light = obj.data
    out = {"type": light.type, "energy": float(light.energy), "color": list(light.color),
           "radius": float(getattr(light, "shadow_soft_size", 0.0))}
    if light.type == "SPOT":
        out.update(spot_size=float(light.spot_size), spot_blend=float(light.spot_blend))
    if light.type == "AREA":
        out["size"] = float(light.size)
    if light.type == "SUN":
        out["radius"] = 0.0
    return out


def _world(out_dir: str) -> dict | None:
    world = bpy.context.scene.world
    if world is None:
        return None
    out = {"name": world.name, "color": list(world.color), "strength": 1.0, "hdri_path": None}
    if world.use_nodes and world.node_tree is not None:
        background = next((n for n in world.node_tree.nodes if n.type == "BACKGROUND"), None)
        if background is not None:
            out["color"] = list(background.inputs["Color"].default_value)[:3]
            out["strength"] = float(background.inputs["Strength"].default_value)
            for link in background.inputs["Color"].links:
                if link.from_node.type == "TEX_ENVIRONMENT":
                    out["hdri_path"] = _image_path(link.from_node.image, out_dir)
    return out


def _render_subdivision(options: dict) -> None:
    """Set every Subdivision Surface / Multires modifier's viewport level to what a render evaluates (module doc)."""
    cap = int(options.get("simplify_subdivision_render", 0))
    given = options.get("render_levels")
    given = {} if given is None else given
    for obj in bpy.data.objects:
        for modifier in obj.modifiers:
            if modifier.type not in ("SUBSURF", "MULTIRES"):
                continue
            level = given if isinstance(given, int) else given.get(obj.name)
            if level is not None and modifier.type == "SUBSURF":
                modifier.render_levels = int(level)
            level = min(modifier.render_levels, cap) if cap > 0 else modifier.render_levels
            if modifier.type == "SUBSURF":
                modifier.levels = level
            else:
                modifier.levels = min(level, modifier.total_levels)


def main(blend: str, out_dir: str, options: dict) -> None:
    bpy.ops.wm.open_mainfile(filepath=blend)
    pattern = re.compile(options["entities"]) if options.get("entities") else None
    types = {t.upper() for t in options.get("obj_types", ["mesh", "empty"])}
    _render_subdivision(options)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    objects, arrays = [], {}
    for obj in bpy.context.scene.objects:
        if pattern is not None and not pattern.fullmatch(obj.name):
            continue
        record = {"name": obj.name, "type": obj.type, "matrix_world": [list(row) for row in obj.matrix_world],
                  "custom_properties": _custom_properties(obj),
                  "parent": obj.parent.name if obj.parent else None, "hidden": bool(obj.hide_render)}
        if obj.type == "MESH" and "MESH" in types:
            prefix = f"m{len(objects)}"
            record.update(arrays=prefix, **_mesh_arrays(obj, depsgraph, prefix, arrays))
            record["materials"] = [_material(slot.material, out_dir, options) for slot in obj.material_slots]
        elif obj.type == "LIGHT" and "LIGHT" in types:
            record["light"] = _light(obj)
        elif obj.type == "EMPTY" and "EMPTY" in types:
            pass
        else:
            continue
        objects.append(record)
    scene = {"objects": objects, "world": _world(out_dir), "blender_version": list(bpy.app.version)}
    np.savez(os.path.join(out_dir, "arrays.npz"), **arrays)
    with open(os.path.join(out_dir, "scene.json"), "w", encoding="utf-8") as handle:
        json.dump(scene, handle)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], json.loads(sys.argv[3]))
