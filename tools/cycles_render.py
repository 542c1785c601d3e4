"""Blender Cycles worker for the color benchmarks: renders an exported scene (tools/cycles_export.py) keypoint by
keypoint, on request.

Over 300 lines: one process inside Blender builds the scene and answers render requests, with its EXR reader.

Runs inside its own virtual environment (``bpy`` from PyPI needs Python 3.11 and numpy < 2), started by
tools/cycles_worker.py, which creates ``.venv-bpy`` on demand::

    .venv-bpy/bin/python tools/cycles_render.py SCENE.npz

Protocol (one JSON object per line): after building the scene the worker answers
``{"ready": true, "blender": ..., "setup_s": ...}``; then each request line on stdin,
``{"index": i, "light_tree": bool, "seed": int, "save": path-or-null}`` (optionally ``"mode"``:
``"blenderproc"`` - BlenderProc 2.8's render defaults, or ``"reference"`` - the same estimator at a fixed
``"spp"`` without adaptive sampling or denoising; ``"cycles"``: a mapping of ``scene.cycles`` attributes set
after the mode, for experiments; ``"sample_counts"``: a ``.npy`` path that receives the samples each pixel got,
float32 H x W, from Cycles' "Debug Sample Count" pass), is answered with
``{"seconds": wall, "cpu_s": cpu}`` (the time of ``bpy.ops.render.render`` alone); ``{"quit": true}`` ends
it with its peak RSS. Requests one at a time let the benchmark interleave Cycles with Mitsuba keypoint by
keypoint, so both see the same machine noise; while waiting the worker is idle.

Blender writes render progress to stdout, so the protocol goes through a private copy of the original
stdout and fd 1 is pointed at stderr (which the benchmark discards).
"""
from __future__ import annotations

import json
import os
import resource
import sys
import time

import bpy
import mathutils
import numpy as np


def _material(name: str, spec: dict, texture: np.ndarray | None = None) -> bpy.types.Material:
    """Diffuse BSDF for hybridgen's diffuse materials (specular = metallic = 0, as its Mitsuba translation),
    Principled BSDF otherwise; emissive ones add an Emission shader (Cycles emits from both sides, like
    hybridgen's two-sided Mitsuba emitters)."""
    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # always true from Blender 5 on (and deprecated)
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    color = (*spec["color"][:3], 1.0)
    if spec["kind"] == "diffuse":
        surface = nodes.new("ShaderNodeBsdfDiffuse")
        surface.inputs["Color"].default_value = color
        surface.inputs["Roughness"].default_value = 0.0
    else:
        surface = nodes.new("ShaderNodeBsdfPrincipled")
        surface.inputs["Base Color"].default_value = color
        surface.inputs["Roughness"].default_value = spec["roughness"]
        surface.inputs["Metallic"].default_value = spec["metallic"]
        surface.inputs["Specular IOR Level"].default_value = spec["specular"]
        surface.inputs["Transmission Weight"].default_value = spec.get("transmission", 0.0)
        surface.inputs["IOR"].default_value = spec.get("ior", 1.45)
        extra = dict(spec.get("extra", {}))  # Principled inputs beyond hybridgen's Material fields
        if "subsurface_method" in extra:  # a node property, not an input
            surface.subsurface_method = extra.pop("subsurface_method")
        sockets = {socket.name: socket for socket in surface.inputs}  # unavailable ones too (Subsurface IOR)
        for key, value in extra.items():
            socket = sockets[key.replace("_", " ").title().replace("Ior", "IOR")]  # coat_ior -> "Coat IOR"
            rgba = isinstance(value, list) and len(socket.default_value) == 4  # colors; Subsurface Radius is XYZ
            socket.default_value = (*value, 1.0) if rgba else value
    if texture is not None:  # sRGB uint8 H x W x 3, sampled with the mesh's UV map
        image = bpy.data.images.new(name + "_texture", texture.shape[1], texture.shape[0], alpha=True)
        rgba = np.concatenate([texture[::-1] / 255.0, np.ones(texture.shape[:2] + (1,))], axis=-1)
        image.pixels.foreach_set(rgba.astype(np.float32).ravel())
        node = nodes.new("ShaderNodeTexImage")
        node.image = image
        links.new(node.outputs["Color"], surface.inputs["Color" if spec["kind"] == "diffuse" else "Base Color"])
    shader = surface.outputs["BSDF"]
    emission = spec["emission"]
    if max(emission) > 0:
        emit = nodes.new("ShaderNodeEmission")
        strength = max(emission)
        emit.inputs["Color"].default_value = (*[c / strength for c in emission], 1.0)
        emit.inputs["Strength"].default_value = strength
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(emit.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]
    links.new(shader, output.inputs["Surface"])
    return material


def build(path: str) -> tuple[bpy.types.Scene, bpy.types.Object, np.ndarray]:
    data = np.load(path, allow_pickle=False)
    meta = json.loads(str(data["meta"]))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for index, obj in enumerate(meta["objects"]):
        vertices, faces = data[f"v{index}"], data[f"f{index}"]
        mesh = bpy.data.meshes.new(obj["name"])
        mesh.from_pydata(vertices.tolist(), [], faces.tolist())
        if f"n{index}" in data:  # smooth shading with the same per-vertex normals Mitsuba gets
            mesh.shade_smooth()
            mesh.normals_split_custom_set_from_vertices(data[f"n{index}"].tolist())
        if f"uv{index}" in data:
            uvs = data[f"uv{index}"]
            layer = mesh.uv_layers.new(name="uv")
            corners = np.zeros(len(mesh.loops), dtype=np.int64)
            mesh.loops.foreach_get("vertex_index", corners)
            layer.data.foreach_set("uv", uvs[corners].astype(np.float32).ravel())
        mesh.update()
        mesh.materials.append(_material(obj["name"], obj, data[f"tex{index}"] if f"tex{index}" in data else None))
        scene.collection.objects.link(bpy.data.objects.new(obj["name"], mesh))
    world = bpy.data.worlds.new("world")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*meta["world"], 1.0)
    background.inputs["Strength"].default_value = 1.0
    if meta.get("hdri"):
        environment = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        environment.image = bpy.data.images.load(meta["hdri"]["path"])
        mapping = world.node_tree.nodes.new("ShaderNodeMapping")
        coords = world.node_tree.nodes.new("ShaderNodeTexCoord")
        # the node turns the lookup direction by this angle (the export gives minus hybridgen's hdri_rotation)
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, meta["hdri"]["rotation"])
        world.node_tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        world.node_tree.links.new(mapping.outputs["Vector"], environment.inputs["Vector"])
        world.node_tree.links.new(environment.outputs["Color"], background.inputs["Color"])
        background.inputs["Strength"].default_value = meta["hdri"]["strength"]
    scene.world = world
    for index, spec in enumerate(meta.get("lights", [])):  # Blender's units, as hybridgen's lights
        light = bpy.data.lights.new(f"light{index}", spec["type"])
        light.energy = spec["energy"]
        light.color = spec["color"]
        if spec["type"] in ("POINT", "SPOT"):
            light.shadow_soft_size = spec.get("radius", 0.0)
        if spec["type"] == "SUN":
            light.angle = 0.0
        light_object = bpy.data.objects.new(f"light{index}", light)
        light_object.matrix_world = mathutils.Matrix(spec["local2world"])
        scene.collection.objects.link(light_object)

    width, height = meta["resolution"]
    K = np.array(meta["K"])
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit = "HORIZONTAL"
    camera_data.sensor_width = 36.0
    camera_data.lens = K[0, 0] * 36.0 / width
    # Shifts are in units of the film width; K's principal point is in pixel-centre coordinates.
    camera_data.shift_x = -(K[0, 2] - (width - 1) / 2) / width
    camera_data.shift_y = (K[1, 2] - (height - 1) / 2) / width
    camera_data.clip_start, camera_data.clip_end = meta["clip"]
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = meta["spp"]
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    bounces = meta["max_bounces"]  # Cycles' count: 0 = direct light only (Mitsuba max_depth = bounces + 2)
    scene.cycles.max_bounces = bounces
    scene.cycles.diffuse_bounces = scene.cycles.glossy_bounces = scene.cycles.transmission_bounces = bounces
    scene.cycles.min_light_bounces = meta["min_bounces"]  # no Russian roulette before it, as Mitsuba's rr_depth
    scene.cycles.pixel_filter_type = "BOX"  # hybridgen's film: one-pixel box filter
    scene.cycles.filter_width = 1.0
    scene.render.use_persistent_data = True  # keep the synced scene and BVH between renders (camera moves only)
    scene.render.threads_mode = "FIXED"
    scene.render.threads = meta["threads"]
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.view_settings.view_transform = "Standard"  # plain sRGB, as hybridgen's colors
    scene.view_settings.look = "None"
    return scene, camera, data["poses"]


def blenderproc_defaults(scene: bpy.types.Scene, reference: bool, spp: int) -> None:
    """BlenderProc 2.8's render defaults (its Initializer and DefaultConfig): adaptive sampling to noise
    threshold 0.01 with at most 1024 spp, Open Image Denoise with albedo and normals, light tree off, bounces
    max 3 / diffuse 3 / glossy 0 / transmission 0 / transparent 8 / volume 0; Cycles' own defaults elsewhere
    (indirect clamp 10, filter glossy 1, Blackman-Harris 1.5 px pixel filter, Russian roulette after 0
    minimum bounces). ``reference``: the same estimator at a fixed ``spp``, no adaptivity, no denoising."""
    cycles = scene.cycles
    cycles.use_adaptive_sampling = not reference
    cycles.adaptive_threshold = 0.01
    cycles.adaptive_min_samples = 0
    cycles.samples = spp if reference else 1024
    cycles.use_denoising = not reference
    cycles.denoiser = "OPENIMAGEDENOISE"
    cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    cycles.use_light_tree = False
    cycles.max_bounces, cycles.diffuse_bounces, cycles.glossy_bounces = 3, 3, 0
    cycles.transmission_bounces, cycles.transparent_max_bounces, cycles.volume_bounces = 0, 8, 0
    cycles.min_light_bounces = 0
    cycles.sample_clamp_direct, cycles.sample_clamp_indirect, cycles.blur_glossy = 0.0, 10.0, 1.0
    cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    cycles.filter_width = 1.5


def _exr_header(raw: bytes, position: int) -> tuple[dict[str, bytes], int]:
    """One OpenEXR header's attributes (name -> value bytes) and the position after its closing null byte."""
    attributes = {}
    while raw[position] != 0:  # name, type, size, value
        end = raw.index(b"\0", position)
        type_end = raw.index(b"\0", end + 1)
        size = int.from_bytes(raw[type_end + 1:type_end + 5], "little")
        attributes[raw[position:end].decode()] = raw[type_end + 5:type_end + 5 + size]
        position = type_end + 5 + size
    return attributes, position + 1


def _exr_channel_list(value: bytes) -> list[tuple[str, int]]:
    """(name, pixel type) of each entry of an EXR ``chlist`` attribute, in file order."""
    channels, at = [], 0
    while value[at] != 0:
        end = value.index(b"\0", at)
        channels.append((value[at:end].decode(), int.from_bytes(value[end + 1:end + 5], "little")))
        at = end + 17  # pixel type, pLinear + 3 reserved bytes, x and y sampling
    return channels


def read_exr_channels(path: str) -> dict[str, np.ndarray]:
    """Channels (float32 H x W, top row first) of an uncompressed scanline OpenEXR file, single- or multi-part,
    as Blender writes a multilayer EXR with ``exr_codec = "NONE"`` (names ``layer.pass.channel``; Blender 5
    writes one part per pass). The pip ``bpy`` wheel has no Python EXR reader, and a render result's passes
    are not readable from Python otherwise."""
    raw = open(path, "rb").read()
    if int.from_bytes(raw[:4], "little") != 20000630:
        raise ValueError(f"{path}: not an OpenEXR file")
    multipart = bool(raw[5] & 0x10)
    headers, position = [], 8
    while True:
        header, position = _exr_header(raw, position)
        headers.append(header)
        if not multipart or raw[position] == 0:
            position += multipart  # the empty header that ends a multi-part file's list
            break
    out: dict[str, np.ndarray] = {}
    dtypes = {0: "<u4", 1: "<f2", 2: "<f4"}
    for part, header in enumerate(headers):
        if header["compression"][0] != 0:
            raise ValueError(f"{path}: only uncompressed EXR files are read here")
        window = np.frombuffer(header["dataWindow"], "<i4")
        width, height = int(window[2] - window[0] + 1), int(window[3] - window[1] + 1)
        channels = _exr_channel_list(header["channels"])
        images = {name: np.zeros((height, width), np.float32) for name, _ in channels}
        offsets = np.frombuffer(raw, "<u8", height, position)  # one scanline per chunk when uncompressed
        position += 8 * height
        for offset in map(int, offsets):  # [part number,] y, byte count, then each channel's row in turn
            offset += 4 * multipart
            y = int.from_bytes(raw[offset:offset + 4], "little", signed=True) - int(window[1])
            at = offset + 8
            for name, pixel_type in channels:
                row = np.frombuffer(raw, dtypes[pixel_type], width, at)
                images[name][y] = row
                at += row.nbytes
        out.update(images)
    return out


def save_sample_counts(scene: bpy.types.Scene, path: str) -> None:
    """The finished render's "Debug Sample Count" pass (enabled before rendering) as samples per pixel
    (float32 H x W) in ``path``
    (.npy): written through an uncompressed multilayer EXR next to it, which is removed."""
    settings = scene.render.image_settings
    # Blender 5 picks a multilayer EXR by media_type, Blender 4.2 (BlenderProc's) by file_format
    kind, multilayer = (("media_type", "MULTI_LAYER_IMAGE") if hasattr(settings, "media_type")
                        else ("file_format", "OPEN_EXR_MULTILAYER"))
    saved = (getattr(settings, kind), settings.exr_codec, settings.color_depth)
    exr = path + ".exr"
    setattr(settings, kind, multilayer)
    settings.exr_codec, settings.color_depth = "NONE", "32"
    try:
        bpy.data.images["Render Result"].save_render(exr, scene=scene)
    finally:
        setattr(settings, kind, saved[0])
        settings.exr_codec, settings.color_depth = saved[1], saved[2]
    channels = read_exr_channels(exr)
    os.remove(exr)
    names = [name for name in channels if "Sample Count" in name or "SampleCount" in name]
    if not names:
        raise RuntimeError(f"no sample-count channel among {sorted(channels)}")
    # Cycles writes each pixel's count divided by the render's sample count (1.0 = scene.cycles.samples)
    np.save(path, np.rint(channels[names[0]] * scene.cycles.samples).astype(np.float32))


def main(path: str) -> None:
    protocol = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # Blender's progress lines go to stderr
    start = time.perf_counter()
    scene, camera, poses = build(path)
    protocol.write(json.dumps({"ready": True, "blender": bpy.app.version_string,
                               "setup_s": time.perf_counter() - start}) + "\n")
    for line in sys.stdin:
        request = json.loads(line)
        if request.get("quit"):
            break
        pose = np.asarray(poses[request["index"]]) @ np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV -> Blender axes
        camera.matrix_world = mathutils.Matrix(pose.tolist())  # (a plain nested list would be read transposed)
        scene.cycles.use_light_tree = bool(request["light_tree"])
        if request.get("mode") in ("blenderproc", "reference"):
            blenderproc_defaults(scene, request.get("mode") == "reference", int(request.get("spp", 1024)))
        for key, value in request.get("cycles", {}).items():  # experiments: scene.cycles attributes set last
            setattr(scene.cycles, key, value)
        scene.cycles.seed = int(request.get("seed", 0)) % 2**31  # Cycles' seed is an int32
        scene.view_layers[0].cycles.pass_debug_sample_count = bool(request.get("sample_counts"))
        cpu, wall = time.process_time(), time.perf_counter()
        bpy.ops.render.render(write_still=False)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        if request.get("save"):  # PNG (8-bit sRGB, the view transform applied) or, for a .exr path, linear float
            settings = scene.render.image_settings
            exr = request["save"].endswith(".exr")
            settings.file_format, settings.color_depth = ("OPEN_EXR", "32") if exr else ("PNG", "8")
            bpy.data.images["Render Result"].save_render(request["save"], scene=scene)
        if request.get("sample_counts"):
            save_sample_counts(scene, request["sample_counts"])
        protocol.write(json.dumps({"seconds": wall, "cpu_s": cpu}) + "\n")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    protocol.write(json.dumps({"peak_rss_mib": peak}) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
