"""A hybridgen scene exported for Blender Cycles: the ``.npz`` file tools/cycles_render.py builds its Blender scene
from (and whose content tools/reference_cache.scene_digest keys the color benchmark's Cycles references by).

Units: metres, radians, linear RGB; the camera's ``K`` in pixels.
"""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np


def export_for_cycles(scene: Any, path: Path, spp: int, bounces: int, min_bounces: int,
                      threads: int | None = None) -> None:
    """Meshes in world coordinates (with the world-space vertex normals hybridgen gives Mitsuba), materials
    (base-color textures and UVs included), lights, world (color or HDRI), camera and poses, for
    tools/cycles_render.py, which renders with ``threads`` CPU threads (default: every core)."""
    from hybridgen.render.pathtrace.mitsuba_scene import emitted_radiance

    arrays: dict[str, np.ndarray] = {}
    objects = []
    for i, obj in enumerate(scene.objects):
        arrays[f"v{i}"] = obj.world_vertices().astype(np.float32)
        arrays[f"f{i}"] = obj.faces.astype(np.int32)
        if obj.vertex_normals is not None:
            normals = obj.vertex_normals @ np.linalg.inv(obj.local2world[:3, :3])
            arrays[f"n{i}"] = (normals / np.linalg.norm(normals, axis=1, keepdims=True)).astype(np.float32)
        m = obj.material
        if m.base_color_texture is not None and obj.uvs is not None:
            texture = m.base_color_texture
            if isinstance(texture, (str, Path)):
                from PIL import Image

                texture = np.asarray(Image.open(texture).convert("RGB"))
            arrays[f"tex{i}"] = np.ascontiguousarray(np.asarray(texture)[..., :3], dtype=np.uint8)
            arrays[f"uv{i}"] = np.asarray(obj.uvs, dtype=np.float32)
        diffuse = m.specular == 0 and m.metallic == 0 and m.transmission == 0 and not m.extra  # as bsdf_dict
        objects.append({"name": obj.name, "kind": "diffuse" if diffuse else "principled",
                        "color": [float(c) for c in m.base_color[:3]], "roughness": float(m.roughness),
                        "metallic": float(m.metallic), "specular": float(m.specular),
                        "transmission": float(m.transmission), "ior": float(m.ior),
                        "emission": emitted_radiance(obj).tolist(),
                        # Principled inputs beyond the Material's fields (coat, tint, ...); absent when none, so
                        # existing exports (and the benchmark's reference digests) stay byte-identical
                        **({"extra": {k: list(v) if isinstance(v, (list, tuple)) else v for k, v in m.extra.items()}}
                           if m.extra else {})})
    # AREA lights carry their edge ("size", m); tools/cycles_render_layers.py gives them to Cycles (a square of that
    # edge, spread 180 degrees): scenes without one export as before (the benchmark's reference digests)
    lights = [{"type": light.type, "energy": float(light.energy), "color": [float(c) for c in light.color],
               "radius": float(light.radius), "local2world": np.asarray(light.local2world).tolist(),
               **({"size": float(light.size)} if light.type == "AREA" else {})}
              for light in scene.lights if light.type in ("POINT", "SUN", "AREA")]
    world = scene.world
    intr = scene.camera.intrinsics
    meta = {"objects": objects, "world": (np.asarray(world.color)[:3] * world.strength).tolist(), "lights": lights,
            # "rotation": the Z angle of Blender's Mapping node between the world's Generated coordinates and the
            # Environment Texture (BlenderProc's set_world_background_hdr_img wiring). The node turns the lookup
            # direction, so the map turns the other way: hybridgen's hdri_rotation (the map turned counter-clockwise
            # about +Z, README) is the node's minus that angle.
            "hdri": {"path": str(world.hdri_path), "strength": float(world.strength),
                     "rotation": -float(world.hdri_rotation)} if world.hdri_path else None,
            "resolution": [intr.width, intr.height], "K": intr.K.tolist(), "clip": [intr.clip_start, intr.clip_end],
            "spp": spp, "max_bounces": bounces, "min_bounces": min_bounces, "threads": threads or os.cpu_count() or 2}
    np.savez(path, meta=np.array(json.dumps(meta)), poses=np.stack(scene.camera.keypoints), **arrays)
