"""Translation of the renderer-agnostic scene into a Mitsuba 3 scene dictionary (done once per run).

Geometry is handed over as in-memory meshes in world coordinates (flat-shaded meshes without vertex
normals stay flat). Materials become Mitsuba BSDFs (:mod:`hybridgen.render.pathtrace.mitsuba_materials`); lights
map as follows (Blender's units, as BlenderProc configs give them):

- POINT of power P [W]: ``point`` with intensity P / (4 pi) [W/sr], uniform in all directions.
- SPOT: ``spot`` with the same intensity, cutoff = spot_size / 2, falloff from spot_blend.
- SUN of strength E [W/m^2]: ``directional`` with irradiance E, shining along the light's -z axis.
- AREA of power P, square of edge ``size``: a one-sided emitting rectangle of radiance P / (size^2 pi),
  facing the light's -z axis.
- Emissive materials (``emission`` or ``emission_texture`` x ``emission_strength``): an ``area`` emitter on
  the mesh, radiance emission x strength (:mod:`hybridgen.render.pathtrace.material_emission`), on both sides (a
  flipped copy a hair behind the surface emits backwards).
- Opaque BSDFs are two-sided (Mitsuba's are one-sided; Blender's and most real meshes' are not).
- World: ``constant`` radiance color x strength, or an ``envmap`` HDRI (scale = strength, rotated about +Z).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ...input_paths import not_found, utf8_path
from ...errors import InputError
from ...io.image_check import check_image_file
from ...scene.light import Light
from ...scene.mesh_object import MeshObject
from ...scene.scene import Scene, World
from ...scene.vertex_normals import angle_weighted_normals
from . import light_selection
from .material_emission import emitted_radiance, radiance_texture
from .mitsuba_instances import instanced_entries
from .mitsuba_materials import VERTEX_COLOR_ATTRIBUTE
from .mitsuba_materials import rgb as _rgb
from .principled_tangent import ATTRIBUTE as RADIAL_TANGENT, needs_radial_tangent, radial_tangents
from .shared_bsdfs import loaded_bsdf

ENVMAP_TO_WORLD = np.array([[0.0, 0, 1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
"""Lays Mitsuba's lat-long map (local +Y up, u = atan2(x, -z) / 2 pi mod 1) out as Blender's equirectangular
mapping (world +Z up, u = 1/2 - atan2(y, x) / 2 pi): image centre column = world +X, a quarter from the left
= +Y, top row = +Z, so an HDRI lights a scene from the same side as in BlenderProc."""


def _world_normals(obj: MeshObject) -> np.ndarray:
    """Unit vertex normals in world axes: the mesh's own, else angle-weighted face normals."""
    local = obj.vertex_normals if obj.vertex_normals is not None else angle_weighted_normals(obj.vertices, obj.faces)
    normals = local @ np.linalg.inv(obj.local2world[:3, :3])
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)


def mesh_shape(obj: MeshObject, *, back_side: bool = False, sampling_weight: float = 1.0,
               bsdfs: dict[Any, Any] | None = None) -> Any:
    """An in-memory Mitsuba mesh of ``obj`` in world coordinates, with its BSDF (and emitter if emissive).

    ``back_side`` gives the emitting back of an emissive mesh: faces flipped and moved a hair (1e-6 of the
    object's size) behind the surface, so each side emits once, like Blender's two-sided emission.
    ``sampling_weight``: the emitter's share of light samples (see :mod:`hybridgen.render.pathtrace.light_selection`).
    """
    import mitsuba as mi

    props = mi.Properties()
    colored = obj.vertex_colors is not None and obj.material.base_color_from_vertices
    has_uv = obj.uvs is not None and len(obj.uvs) == len(obj.vertices)
    props["bsdf"] = loaded_bsdf(obj.material, obj.name, vertex_colors=colored, uvs=has_uv, cache=bsdfs)
    radiance = emitted_radiance(obj)
    if np.any(radiance > 0):
        props["emitter"] = mi.load_dict({"type": "area", "radiance": radiance_texture(obj),
                                         "sampling_weight": float(sampling_weight)})
    smooth = obj.vertex_normals is not None
    name = obj.name + (".back" if back_side else "")
    mesh = mi.Mesh(name, len(obj.vertices), len(obj.faces), props=props, has_vertex_normals=smooth,
                   has_vertex_texcoords=has_uv)
    params = mi.traverse(mesh)
    positions, faces = obj.world_vertices(), obj.faces
    normals = _world_normals(obj) if smooth or back_side else None
    if back_side:
        assert normals is not None
        size = float(np.linalg.norm(np.ptp(positions, axis=0)))
        positions = positions - normals * (1e-6 * max(size, 1e-3))
        faces, normals = faces[:, ::-1], -normals
    params["vertex_positions"] = jit_buffer(positions, np.float32)
    params["faces"] = jit_buffer(faces, np.uint32)
    if smooth:
        assert normals is not None
        params["vertex_normals"] = jit_buffer(normals, np.float32)
    if has_uv:
        uv = np.array(obj.uvs, dtype=np.float32)
        uv[:, 1] = 1.0 - uv[:, 1]  # file UVs have v up; Mitsuba's bitmap rows run top-down
        params["vertex_texcoords"] = jit_buffer(uv, np.float32)
    params.update()
    del params  # holding traversal wrappers slows later renders (measured in scalar mode)
    if colored:
        mesh.add_attribute(VERTEX_COLOR_ATTRIBUTE, 3, jit_buffer(obj.vertex_colors, np.float32))
    if needs_radial_tangent(obj.material):  # Blender's default anisotropy tangent (principled_tangent.py)
        mesh.add_attribute(RADIAL_TANGENT, 3, jit_buffer(radial_tangents(obj.vertices, obj.local2world), np.float32))
    return mesh


JIT_ALIGNMENT = 64
"""Bytes: where the mesh buffers handed to Mitsuba start (a cache line, the widest SIMD register)."""


def jit_buffer(array: Any, dtype: Any) -> np.ndarray:
    """A flat C-contiguous copy of ``array`` as ``dtype`` whose data starts on a :data:`JIT_ALIGNMENT`-byte
    boundary, for a Mitsuba mesh buffer.

    With plain NumPy arrays (which start wherever ``malloc`` put them) the path kernels Dr.Jit traced varied
    from process to process - the IR of two runs differed in one mesh's texcoord gather, a packet load of the
    pair in one and two scalar gathers in the other - and a varied kernel misses Dr.Jit's kernel cache: on the
    tabletop of tools/color_quality.py 3 of 8 warm runs compiled the three path kernels again (~1.5 s of CPU
    each time). With aligned buffers: 0 of 8. (The other cause of such misses was Mitsuba's parallel scene
    loader: :data:`hybridgen.render.pathtrace.path_trace.SERIAL_SCENE_LOAD`.) The image bytes are the same either way."""
    flat = np.asarray(array, dtype=dtype).reshape(-1)
    raw = np.empty(flat.size + JIT_ALIGNMENT // flat.itemsize, dtype=dtype)
    start = (-raw.ctypes.data % JIT_ALIGNMENT) // flat.itemsize
    out = raw[start:start + flat.size]
    out[...] = flat
    return out


def light_dict(light: Light) -> dict[str, Any]:
    """Mitsuba emitter (or emitting rectangle) for ``light``; see the module docstring for units."""
    import mitsuba as mi

    if not math.isfinite(light.energy) or light.energy < 0:
        raise InputError(f"light '{light.name}': energy must be >= 0, got {light.energy}")
    color = np.asarray(light.color, float)
    position = light.local2world[:3, 3].tolist()
    if light.type in ("POINT", "SPOT"):
        intensity = _rgb(color * light.energy / (4 * math.pi))
        if light.type == "POINT":
            return {"type": "point", "position": position, "intensity": intensity}
        cutoff = math.degrees(light.spot_size / 2)
        # Mitsuba's spot looks along its local +z; hybridgen lights shine along -z.
        flip = mi.ScalarTransform4f((light.local2world @ np.diag([1.0, -1.0, -1.0, 1.0])).tolist())
        return {"type": "spot", "to_world": flip, "intensity": intensity, "cutoff_angle": cutoff,
                "beam_width": cutoff * (1 - min(max(light.spot_blend, 0.0), 1.0))}
    if light.type == "SUN":
        direction = (-light.local2world[:3, 2]).tolist()
        return {"type": "directional", "direction": direction, "irradiance": _rgb(color * light.energy)}
    # AREA: Mitsuba's rectangle spans [-1, 1]^2 in local xy and faces local +z: scale, then flip to -z.
    half = light.size / 2
    shape_to_world = light.local2world @ np.diag([half, -half, -1.0, 1.0])
    radiance = color * light.energy / (light.size ** 2 * math.pi)
    return {"type": "rectangle", "to_world": mi.ScalarTransform4f(shape_to_world.tolist()),
            "bsdf": {"type": "diffuse", "reflectance": _rgb([0, 0, 0])},
            "emitter": {"type": "area", "radiance": _rgb(radiance)}}


def world_dict(world: World) -> dict[str, Any] | None:
    """The background emitter; None for a black world (an emitter of zero radiance would still take its
    share of the light samples)."""
    import mitsuba as mi

    if world.strength < 0 or not math.isfinite(world.strength):
        raise InputError(f"world strength must be >= 0, got {world.strength}")
    if world.hdri_path:
        path = Path(world.hdri_path)
        if not path.is_file():
            raise InputError(not_found("HDRI file", path))
        check_image_file(path, "HDRI file")  # header pixel budget before Mitsuba decodes it
        rotation = np.eye(4)
        c, s = math.cos(world.hdri_rotation), math.sin(world.hdri_rotation)
        rotation[:2, :2] = [[c, -s], [s, c]]
        return {"type": "envmap", "filename": utf8_path(path), "scale": float(world.strength),
                "to_world": mi.ScalarTransform4f((rotation @ ENVMAP_TO_WORLD).tolist())}
    radiance = np.asarray(world.color, float)[:3] * world.strength
    if not np.any(radiance > 0):
        return None
    return {"type": "constant", "radiance": _rgb(radiance)}


def _hdri_mean_radiance(world: World) -> float:
    """Mean linear pixel value of the world's HDRI times its strength."""
    import mitsuba as mi

    bitmap = mi.Bitmap(utf8_path(world.hdri_path))
    bitmap = bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False)
    return float(np.mean(np.array(bitmap))) * world.strength


def scene_dict(scene: Scene) -> dict[str, Any]:
    """Everything but the sensor and integrator, keyed by stable names; every emitter carries a
    ``sampling_weight`` proportional to its power (:mod:`hybridgen.render.pathtrace.light_selection`)."""
    out: dict[str, Any] = {"type": "scene"}
    radius = light_selection.scene_radius(scene)
    powers: dict[str, float] = {}
    world = world_dict(scene.world)
    if world is not None:
        mean = (_hdri_mean_radiance(scene.world) if scene.world.hdri_path
                else float(np.mean(np.asarray(scene.world.color, float)[:3])) * scene.world.strength)
        powers["world"] = light_selection.world_power(scene.world, mean, radius)
    emissive = [obj for obj in scene.objects if np.any(emitted_radiance(obj) > 0)]
    for obj in emissive:
        powers[f"object_{obj.instance_id}"] = light_selection.mesh_side_power(obj, emitted_radiance(obj))
    for index, light in enumerate(scene.lights):
        powers[f"light_{index}"] = light_selection.light_power(light, radius)
    weights = light_selection.normalised(powers)
    if world is not None:
        if light_selection.constant_world_unsampled(scene.world, len(powers) - 1):
            weights = light_selection.normalised({k: v for k, v in powers.items() if k != "world"})
            weights["world"] = 0.0
        out["world"] = {**world, "sampling_weight": weights["world"]}
    bsdfs: dict[Any, Any] = {}  # equal materials share one BSDF (textures read once)
    shared, instanced = instanced_entries(scene.objects, lambda o: mesh_shape(o, bsdfs=bsdfs),
                                          lambda o: f"object_{o.instance_id}" in weights
                                          or needs_radial_tangent(o.material))  # world-space attribute
    out.update(shared)
    for obj in scene.objects:
        key = f"object_{obj.instance_id}"
        if obj.instance_id in instanced:  # one shapegroup per shared geometry (render/pathtrace/mitsuba_instances.py)
            continue
        out[key] = mesh_shape(obj, sampling_weight=weights.get(key, 1.0), bsdfs=bsdfs)
        if key in weights:
            out[f"{key}_back"] = mesh_shape(obj, back_side=True, sampling_weight=weights[key], bsdfs=bsdfs)
    for index, light in enumerate(scene.lights):
        description = light_dict(light)
        weight = weights[f"light_{index}"]
        if "emitter" in description:  # an AREA light: an emitting rectangle
            description["emitter"]["sampling_weight"] = weight
        else:
            description["sampling_weight"] = weight
        out[f"light_{index}"] = description
    return out
